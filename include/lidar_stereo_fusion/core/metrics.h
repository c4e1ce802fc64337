// KITTI depth-completion metrics and disparity bad-pixel rates.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {

/// Scores of one image over the pixels where the reference has a value.
struct DepthMetrics {
  double mae_mm = 0, rmse_mm = 0;            ///< depth errors [mm]
  double imae_per_km = 0, irmse_per_km = 0;  ///< inverse-depth errors [1/km]
  double bad2 = 0, bad3 = 0, bad5 = 0;       ///< fraction of pixels with disparity error > 2/3/5 px
  double coverage = 0;                       ///< fraction of reference pixels the estimate covers
  int count = 0;                             ///< reference pixels scored
};

/// Scores `depth` [m] against `reference` [m] (0 / NaN = no value) over every reference pixel.
/// Where the estimate has no value (<= 0 or not finite), it counts as depth 0 for MAE/RMSE (as the
/// KITTI devkit does), as inverse depth 0 for iMAE/iRMSE (error 1/z_ref) and as disparity 0 for the
/// bad-pixel rates (error fx B / z_ref), unless `only_covered` is true (then those pixels are
/// skipped; `coverage` is always the covered fraction of all reference pixels). Disparity errors
/// use fx * B / z with the given camera. Throws std::invalid_argument on a size mismatch or an
/// invalid camera. An image without reference pixels gives count 0 and zero scores.
DepthMetrics evaluateDepth(const cv::Mat1f& depth, const cv::Mat1f& reference,
                           const StereoCamera& camera, bool only_covered = false);

/// Scores disparity maps directly (Middlebury): errors in px over reference pixels (> 0).
struct DisparityMetrics {
  double mae_px = 0, rmse_px = 0;
  double bad1 = 0, bad2 = 0, bad3 = 0, bad5 = 0;
  double coverage = 0;
  int count = 0;
};
/// Pixels without estimate (<= 0 or not finite) count as errors of the full reference disparity.
/// Bad-pixel rates count errors strictly greater than 1/2/3/5 px. Throws on a size mismatch.
DisparityMetrics evaluateDisparity(const cv::Mat1f& disparity, const cv::Mat1f& reference);

/// What a map holds, i.e. which of two values is the nearer one.
enum class MapKind {
  kDisparity,  ///< disparity [px]: the larger value is nearer
  kDepth,      ///< depth [m]: the smaller value is nearer
};

/// Fills the empty pixels (<= 0 or not finite) of `map` the way the KITTI devkit's
/// `interpolateBackground` does before scoring (devkit_depth `io_depth.h`, DepthImage; the stereo
/// devkit `io_disp.h` has the same loops):
///  1. rows: a gap with an estimate on both sides, not touching the image border, takes the NEARER
///     of the two bounding values (min depth, as io_depth.h; for kDisparity the max disparity,
///     i.e. the same rule applied to depth fB/d -- NOTE: io_disp.h takes the min *disparity*, the
///     farther value, for disparity maps; we follow the depth devkit for both kinds);
///  2. rows: pixels left of the first / right of the last estimate take that estimate;
///  3. columns: pixels above the first / below the last value of the column (after 1-2) take it.
/// Consequently a row without any estimate stays empty (0) when it lies between two filled rows,
/// exactly as in the devkit; an all-empty map stays empty. Empty pixels come back as 0 (NaN and
/// negative inputs too); valid values are copied unchanged.
cv::Mat1f fillLikeDevkit(const cv::Mat1f& map, MapKind kind);

/// Mean over images, each image weighted equally (KITTI devkit convention). Images with count 0
/// are skipped; `count` is the total over images. No scored image: all zeros, count 0.
DepthMetrics averageMetrics(const std::vector<DepthMetrics>& per_image);
DisparityMetrics averageMetrics(const std::vector<DisparityMetrics>& per_image);

}  // namespace lidar_stereo_fusion
