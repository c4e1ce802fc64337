// Photometric agreement of projected LiDAR with a rectified stereo pair, without ground truth:
// for each LiDAR pixel (u, v, d) of the left image, the sub-pixel shift delta that best matches a
// small grey patch of the left image at (u, v) with the right image at (u - d + delta, v). A LiDAR
// point that lands where the cameras saw its surface gives delta near 0; ego-motion, a time
// offset or a calibration error move it. ROS-free.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace lidar_stereo_fusion {

struct PhotometricCheckParams {
  int patch_radius = 2;        ///< [px] patch of (2 r + 1)^2 pixels (5x5)
  double max_shift = 3.0;      ///< [px] deltas searched in [-max_shift, max_shift]
  double step = 0.25;          ///< [px] search step; the best step is refined by a parabola
  double min_patch_std = 2.0;  ///< [grey levels] flatter left patches are not scored (no texture)
  /// Throws std::invalid_argument for r < 1, step <= 0, max_shift < step, min_patch_std < 0.
  void validate() const;
};

/// The best shift [px] for one LiDAR pixel by zero-mean normalised cross-correlation (ZNCC) of
/// the patches, left at integer (u, v), right sampled bilinearly at (u - d + delta + i, v + j):
/// the grid step with the highest ZNCC, refined by a parabola through it and its neighbours.
/// std::nullopt when a patch leaves either image, the left patch is flatter than min_patch_std,
/// or the best step is at the end of the range (the match is not inside it). `left`, `right`:
/// CV_32F grey images of one size.
std::optional<double> bestShift(const cv::Mat1f& left, const cv::Mat1f& right, int u, int v,
                                double d, const PhotometricCheckParams& params);

/// Shifts of every LiDAR pixel of a frame.
struct PhotometricShifts {
  std::vector<double> shifts;  ///< [px] one per scored LiDAR pixel
  int lidar_pixels = 0;        ///< pixels with a LiDAR disparity (> 0)
  int unscored = 0;            ///< of those, without a shift (edge, flat patch, best at the end)
};
/// bestShift at every pixel of `sparse_disparity` [px] (0 = no point) of the left view.
/// `left_bgr`, `right_bgr`: 8-bit BGR (or grey) rectified images of the disparity's size.
/// Throws std::invalid_argument on other types or sizes, or invalid params.
PhotometricShifts photometricShifts(const cv::Mat& left_bgr, const cv::Mat& right_bgr,
                                    const cv::Mat1f& sparse_disparity,
                                    const PhotometricCheckParams& params = {});

/// Median shift, median |shift| [px] and the fraction with |shift| <= `within` [px] (0 when
/// empty). The signed median tells a bias (the LiDAR nearer than the images say: > 0) from noise.
struct ShiftSummary {
  int count = 0;
  double median = 0.0;
  double median_abs = 0.0;
  double fraction_within = 0.0;
};
ShiftSummary summarizeShifts(const std::vector<double>& shifts, double within = 0.5);

/// One row of a before / after table.
struct ShiftRow {
  std::string name;
  ShiftSummary before;
  std::optional<ShiftSummary> after;  ///< empty: no "after" columns for this row
};
/// A Markdown table: name, scored pixels, median |delta| [px], |delta| <= 0.5 px [%], before and,
/// when any row has one, after.
std::string formatShiftTable(const std::vector<ShiftRow>& rows);

}  // namespace lidar_stereo_fusion
