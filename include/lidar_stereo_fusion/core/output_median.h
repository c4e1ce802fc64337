// Stage 3, last step (not in the paper): a median of the fused disparity over a small square.
//
// Where scan-line pixels the prior locks meet pixels the matcher decided, and where single matches
// go astray, the output holds speckles of one or two pixels. A 3x3 median removes them (and lines
// one pixel wide); measured on every protocol (doc/accuracy.md): KITTI ring hold-outs -2.5 to -3 %
// MAE, Middlebury -2 to -5 %, the dense protocol's RMSE -1.6 %. A 5x5 median removes structures
// under 3 px wide too (a pole 60 m away), so it is not the default.
#pragma once

#include <opencv2/core.hpp>

namespace lidar_stereo_fusion {

/// The median of every pixel's `size` x `size` neighbourhood (3 or 5; the border replicated, as
/// cv::medianBlur, which computes it where the neighbourhood holds no empty pixel). Empty pixels
/// (<= 0, "no value") stay empty and do not count: a pixel beside one takes the median of the
/// values around it (of an even count, the lower middle one). Throws std::invalid_argument for
/// another size or an empty map.
cv::Mat1f medianOfValues(const cv::Mat1f& disparity, int size);

}  // namespace lidar_stereo_fusion
