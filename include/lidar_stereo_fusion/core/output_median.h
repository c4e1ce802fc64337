// Stage 3, last step (not in the paper): a median of the fused disparity over a small square.
//
// Where scan-line pixels the prior locks meet pixels the matcher decided, and where single matches
// go astray, the output holds speckles of one or two pixels. A 3x3 median removes them (and lines
// one pixel wide); measured on every protocol (doc/accuracy.md): KITTI ring hold-outs -2.5 to -3 %
// MAE, Middlebury -2 to -5 %, the dense protocol's RMSE -1.6 %. A 5x5 median removes structures
// under 3 px wide too (a pole 60 m away), so it is not the default. The pipeline's median keeps
// the LiDAR's points that the output agrees with (medianKeepingMeasured): a measurement is no
// speckle, and a plain median erased one-pixel-wide poles the LiDAR had measured.
#pragma once

#include <cmath>

#include <opencv2/core.hpp>

namespace lidar_stereo_fusion {

/// The median of every pixel's `size` x `size` neighbourhood (3 or 5; the border replicated, as
/// cv::medianBlur, which computes it where the neighbourhood holds no empty pixel). Empty pixels
/// (<= 0, "no value") stay empty and do not count: a pixel beside one takes the median of the
/// values around it (of an even count, the lower middle one). Throws std::invalid_argument for
/// another size or an empty map.
cv::Mat1f medianOfValues(const cv::Mat1f& disparity, int size);

/// Whether a projected point (`sparse`, > 0) is still on the scan lines (`lines`) with its value.
inline bool isMeasuredPoint(float sparse, float line) { return sparse > 0.f && sparse == line; }

/// Whether `disparity` (> 0) keeps a measured point's value within `tolerance` [px]: the LiDAR
/// points that the output median and the mixed edge step leave as they are.
inline bool keepsMeasuredPoint(float disparity, float sparse, float line, float tolerance) {
  return isMeasuredPoint(sparse, line) && disparity > 0.f &&
         std::abs(disparity - sparse) <= tolerance;
}

/// The LiDAR points a median must not move: `sparse` (the projection, nearest point per pixel)
/// where the scan lines after Algorithm 1 (`lines`) still hold that very value (Algorithm 1 did
/// not remove it as occluded, no nearer line crosses the pixel), else 0. Throws
/// std::invalid_argument for maps that differ in size.
cv::Mat1f measuredPoints(const cv::Mat1f& sparse, const cv::Mat1f& lines);

/// medianOfValues, except that the measured points (measuredPoints(sparse, lines)) that
/// `disparity` agrees with within `tolerance` [px] keep their value: a LiDAR measurement the
/// matcher confirms is no speckle. (A plain 3x3 median erased 114 such pixels on KITTI frame 20,
/// the dense protocol: one-pixel columns of poles and edges, each > 3 m nearer than what replaced
/// it.) Throws std::invalid_argument as medianOfValues, for maps of another size or a negative or
/// non-finite tolerance.
cv::Mat1f medianKeepingMeasured(const cv::Mat1f& disparity, int size, const cv::Mat1f& sparse,
                                const cv::Mat1f& lines, float tolerance);

}  // namespace lidar_stereo_fusion
