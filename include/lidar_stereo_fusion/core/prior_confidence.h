// Stage 2, last step: how much the up-sampled LiDAR prior can be trusted, pixel by pixel.
//
// BI* (Eq. 3) interpolates every column linearly between the scan lines above and below. That is
// right on a surface and a guess at a depth edge, where the true disparity is the foreground's or
// the background's but the interpolation is a blend of both. The confidence says which is which,
// so that the guided PatchMatch cost (patchmatch/cost.h) lets the LiDAR lead on surfaces and the
// images decide at edges, in wide gaps and where there is no LiDAR at all.
//
// Readings (not in the paper; the paper trusts the prior everywhere with one weight gamma):
//  * A scan-line pixel (measured, or completed along its ring) has confidence 1.
//  * Between two scan lines of a column, up (row y_u, disparity d_u) and down (y_d, d_d), the lines
//    "agree" when one smooth surface explains both. The residual r is the smallest of
//      |d_d - d_u|                         (a front-parallel surface),
//      |d_d - (d_u + s_u (y_d - y_u))|     (the surface of the lines above, extended down),
//      |d_u - (d_d - s_d (y_d - y_u))|     (the surface of the lines below, extended up),
//    where s_u / s_d are the slopes [px/row] between the line pair above / below (when that line
//    exists, |s| <= max_surface_slope). A ground plane or a crease between wall and ground has a
//    small r; an occlusion edge a large one. agree = exp(-max(0, r - edge_tolerance) / edge_sigma).
//  * Where Algorithm 1 removed a scan-line pixel between the two lines, the interval bridges an
//    occlusion: agree is multiplied by removed_factor.
//  * Far from both lines the interpolation is a longer guess (a thin object can hide between
//    them): near = exp(-max(0, dist - near_rows) / decay_rows), dist = rows to the nearer line
//    (decay_rows = 0 turns this off). Confidence = agree * near.
//  * Pixels without a prior (above the top line, below the bottom one, gaps wider than
//    max_interp_rows) have confidence 0.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/upsampling.h"

namespace lidar_stereo_fusion {

struct PriorConfidenceParams {
  double edge_tolerance = 0.5;     ///< residual [px] two lines may differ by and still agree fully
  double edge_sigma = 1.0;         ///< residual [px] beyond the tolerance at which agree = e^-1
  double max_surface_slope = 1.0;  ///< largest slope [px/row] used to extend a surface
  double removed_factor = 0.3;     ///< agree factor of intervals where Algorithm 1 removed a pixel
  double near_rows = 2.0;          ///< [rows] within this distance of a line, no distance decay
  double decay_rows = 16.0;        ///< [rows] e-folding distance beyond near_rows; 0 = no decay
  /// Confidence of the hole fill (fillPriorHoles); 0 = no fill.
  double hole_confidence = 0.2;
  /// [rows] The hole fill extends each column's top value this far up (0 = not at all): above
  /// the top scan line the surface it hit most often goes on (facades, trees, poles), as
  /// IP-Basic's extension to the top assumes; about one ring spacing of a 64-beam LiDAR at mid
  /// range, at hole_confidence so that the images decide.
  int top_extension_rows = 6;
  void validate() const;
};

/// Confidence [0, 1] (unitless) of the prior `prior` interpolated by interpolateBetweenScanLines
/// from `lines` (the scan lines after Algorithm 1), per the readings above. `removed` are the
/// pixels Algorithm 1 cleared (x = column, y = row; may be empty). Pixels where `prior` is 0 get 0.
/// Throws std::invalid_argument for maps of different sizes, an empty map or invalid params.
cv::Mat1f priorConfidence(const ScanLines& lines, const cv::Mat1f& prior,
                          const std::vector<cv::Point>& removed,
                          const PriorConfidenceParams& params);

/// Fills the holes of the prior inside the LiDAR's field of view for the fused method:
///  * rows: a gap between two prior values takes the nearer of the two (the larger disparity), as
///    the KITTI devkit's interpolateBackground does for the benchmark, and the row ends take the
///    first / last value; but above a column's own top value only a value no nearer than that top
///    (+ edge_tolerance) is put (a near object's top points sit higher in the image than a far
///    surface's, and would otherwise spread along the row over the far surfaces above the scan
///    lines: a band of near planes);
///  * columns: below the bottom value, that value; above the top value, that value for
///    params.top_extension_rows rows.
/// Rows without a value stay empty. Filled pixels get confidence params.hole_confidence: a weak
/// pull that decides where the images cannot (a dark, textureless car body that returned few LiDAR
/// points) and yields to them where they can. Nothing happens when hole_confidence is 0. Returns
/// the number of pixels filled. Throws std::invalid_argument for maps of different sizes.
int fillPriorHoles(cv::Mat1f& prior, cv::Mat1f& confidence, const PriorConfidenceParams& params);

}  // namespace lidar_stereo_fusion
