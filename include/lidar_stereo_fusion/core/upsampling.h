// Stage 2: up-sampling of the sparse LiDAR disparity into a dense prior.
//  BI* (the paper's method): horizontal scan-line completion, Algorithm 1 (removal of occluded
//      background points), linear interpolation between scan lines (Eq. 3).
//  BF* (Premebida et al. 2016): bilateral up-sampling, the paper's baseline.
#pragma once

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/lidar_projection.h"

namespace lidar_stereo_fusion {

struct BIParams {
  int max_gap_px = 12;           ///< completion does not bridge gaps wider than this [px]
  double max_jump_disp = 2.0;    ///< nor jumps in disparity larger than this [px]
  double max_disp_diff = 1.5;    ///< Algorithm 1 "Maxdisp": foreground must exceed d by this [px]
  double max_color_diff = 60.0;  ///< Algorithm 1 "Maxcolor": RGB L1 distance [0..765]
  int search_lines = 2;          ///< Algorithm 1 looks at this many scan lines up and down (paper: 1)
  int max_interp_rows = 60;      ///< Eq. 3 does not bridge scan lines further apart than this [rows]
  void validate() const;
};

struct BFParams {
  int radius = 6;             ///< half window [px]
  double sigma_space = 4.0;   ///< spatial Gaussian sigma [px]
  double sigma_range = 2.0;   ///< disparity-range Gaussian sigma [px] (against the nearest point)
  int min_support = 1;        ///< pixels with fewer LiDAR neighbours stay empty
  void validate() const;
};

/// Scan lines after horizontal completion: one value per (ring, column) at most.
struct ScanLines {
  cv::Mat1f disparity;  ///< [px], 0 = no scan line at this pixel
  cv::Mat1s ring;       ///< ring of the line at this pixel, -1 elsewhere
};

/// BI* step 1: interpolates each ring linearly along x between consecutive projected points.
/// Points without a ring (ring < 0) are kept as single pixels.
ScanLines completeScanLines(const SparseDisparity& sparse, const BIParams& params);

/// BI* step 2 (Algorithm 1): clears scan-line pixels that have, both above and below in their
/// column (within `search_lines` scan lines), a pixel with disparity larger by more than
/// max_disp_diff whose image colour is within max_color_diff of the colour at the pixel.
/// `image` is the view's BGR image (CV_8UC3) or grey (CV_8UC1). Returns the number removed.
int removeOccludedPoints(ScanLines& lines, const cv::Mat& image, const BIParams& params);

/// BI* step 3 (Eq. 3): linear interpolation in every column between the nearest scan lines above
/// and below. Pixels above the top or below the bottom line stay 0.
cv::Mat1f interpolateBetweenScanLines(const ScanLines& lines, const BIParams& params);

/// The whole BI* chain. `removed` (optional) receives the Algorithm 1 count.
cv::Mat1f upsampleBI(const SparseDisparity& sparse, const cv::Mat& image, const BIParams& params,
                     int* removed = nullptr, ScanLines* lines_out = nullptr);

/// BF*: bilateral up-sampling of the sparse disparity (no occlusion handling, as in the paper's
/// comparison). Pixels without support stay 0.
cv::Mat1f upsampleBF(const SparseDisparity& sparse, const BFParams& params);

/// Per-pixel search bounds from the scan lines above and below each pixel (paper Sec. III-D):
/// lo/hi = min/max of the line disparities -/+ margin; range = |d_up - d_down|.
/// Pixels with fewer than two lines in their column get lo = hi = range = 0 (meaning "unbounded").
struct ScanLineBounds {
  cv::Mat1f lo, hi;   ///< [px]
  cv::Mat1f range;    ///< Delta_d_max for plane refinement [px]
};
ScanLineBounds computeScanLineBounds(const ScanLines& lines, double margin_px);

}  // namespace lidar_stereo_fusion
