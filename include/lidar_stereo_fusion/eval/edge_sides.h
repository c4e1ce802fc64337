// Which surface a reference shows at a method's own depth edges (issue 31). ROS-free.
//
// At a depth edge a pixel shows two surfaces, and references differ in which one they give it:
// Middlebury's structured light mostly the far one, a z-buffer of LiDAR returns (KITTI's ground
// truth) the nearest return in the pixel, and a blur (IP-Basic's) a depth between the two. This
// counts, for one method's output, the pixels p on the far side of its own edges and what the
// reference has there:
//  * p is an edge pixel when the nearest of its 4-neighbours with a value, q, is nearer by a depth
//    ratio z_p / z_q >= min_ratio (core/mixed_edges.h's kMixedEdgeMinRatio, 1.3, by default);
//  * the reference r at p is "near" when |r - z_q| <= tolerance z_q, else "far" when
//    |r - z_p| <= tolerance z_p, else "between" when z_q < r < z_p, else "other".
// With min_ratio >= 1.3 and tolerance <= 0.1 the near and far intervals do not overlap. A method
// that chose the wrong surface at p pays (z_p - z_q)^2 either way, so where a reference is split
// between near and far no choice of surface lowers the squared error; only a value between the
// two does. Disparity maps (MapKind::kDisparity) are compared as z = 1 / d, so the ratio and the
// classes are the same as for the depth they stand for; the squared errors stay in the map's unit.
#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/metrics.h"

namespace lidar_stereo_fusion {

/// What edgeSides counts (sums: several items add up with +=).
struct EdgeSides {
  int64_t pixels = 0;   ///< edge pixels of the output with a reference
  int64_t near = 0;     ///< ... where the reference has the nearer neighbour's surface
  int64_t far = 0;      ///< ... the pixel's own (farther) surface
  int64_t between = 0;  ///< ... a value between the two, outside both tolerances
  int64_t other = 0;    ///< ... nearer than the near one or farther than the far one
  /// The method's squared error over its edge pixels and over every reference pixel, in the map's
  /// unit squared (m^2 or px^2), after the devkit fill (as scored).
  double edge_sq_error = 0;
  double total_sq_error = 0;

  EdgeSides& operator+=(const EdgeSides& o);
};

/// The counts of one output against its reference (both the same size; values <= 0 or not finite
/// are empty). The output is filled like the devkit first (fillLikeDevkit), as the protocols
/// score it. Throws std::invalid_argument on a size mismatch or min_ratio <= 1 or tolerance
/// outside [0, 1).
EdgeSides edgeSides(const cv::Mat1f& output, const cv::Mat1f& reference, MapKind kind,
                    double min_ratio = 1.3, double tolerance = 0.1);

}  // namespace lidar_stereo_fusion
