// The check for near planes along the top of the LiDAR's view (issue: "no band at the top of the
// LiDAR's view"). Above the topmost scan line the method is stereo alone; a fault there shows as
// bands of near disparity along the rows just above the top line, across far facades and trees.
//
// Per column x whose topmost LiDAR pixel (row t, depth z_t) is beyond `min_depth` (10 m), the
// output's depth in the `rows` (6) rows above t is looked at. The column is "banded" when the
// nearest of those depths, z_b at row y_b, is under `ratio` (0.6) x z_t. A banded column is
// "excused" when a nearer surface is really there, which the data shows in one of two ways:
//  * the LiDAR: a point within `neighbour_cols` (3) columns, in rows [y_b - rows, t + 2], at a
//    depth within `depth_tolerance` (20 %) of z_b: an object that rises above the top line
//    (a pole, a trunk, a sign) returned points at that depth beside the column;
//  * the images: the zero-mean NCC cost (1 - NCC, grey, 7 x 7) of the left pixel (x, y_b) against
//    the right image at the output's disparity is lower by `ncc_margin` (0.2) than at the top
//    point's disparity: the images match the nearer surface clearly better.
// ROS-free; used by a real-data test and by anyone auditing a drive.
#pragma once

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {

struct TopBandParams {
  double min_depth = 10.0;       ///< [m] columns whose top point is nearer are not looked at
  int rows = 6;                  ///< [rows] looked at above the top point
  double ratio = 0.6;            ///< banded when the output is nearer than ratio x top depth
  int neighbour_cols = 3;        ///< [px] LiDAR evidence searched this far beside the column
  double depth_tolerance = 0.2;  ///< relative depth agreement of that evidence
  double ncc_margin = 0.2;       ///< image evidence: NCC cost lower by at least this
};

struct TopBandReport {
  int columns = 0;  ///< columns looked at (top point beyond min_depth, an output value above it)
  int banded = 0;   ///< of those, banded and not excused
  int excused = 0;  ///< banded, but a nearer surface is shown by the LiDAR or the images
  double bandedShare() const { return columns > 0 ? static_cast<double>(banded) / columns : 0.0; }
};

/// Counts the banded columns of one frame. `fed` is the left-view sparse disparity fed to the
/// method [px, 0 = none], `disparity` the method's output [px, 0 = none], `left` / `right` the
/// rectified images (BGR or grey, the size of the maps), `camera` gives f B. Throws
/// std::invalid_argument on empty inputs or sizes that differ.
TopBandReport checkTopBand(const cv::Mat1f& fed, const cv::Mat1f& disparity, const cv::Mat& left,
                           const cv::Mat& right, const StereoCamera& camera,
                           const TopBandParams& params = TopBandParams());

}  // namespace lidar_stereo_fusion
