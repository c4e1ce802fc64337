// The check for near planes along the top of the LiDAR's view (readings in top_band_check.h).
#include "lidar_stereo_fusion/eval/top_band_check.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace lidar_stereo_fusion {

namespace {

constexpr int kNccRadius = 3;  ///< 7 x 7 window

cv::Mat1b toGrey(const cv::Mat& image) {
  cv::Mat1b grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else {
    grey = image;
  }
  return grey;
}

/// 1 - zero-mean NCC of the 7 x 7 window of `left` at (x, y) against `right` at (x - d, y)
/// (d rounded to the nearest pixel); 2 (the worst) when a window leaves an image or is flat.
double nccCost(const cv::Mat1b& left, const cv::Mat1b& right, int x, int y, double d) {
  const int xr = static_cast<int>(std::lround(x - d));
  const int r = kNccRadius;
  if (y - r < 0 || y + r >= left.rows || x - r < 0 || x + r >= left.cols || xr - r < 0 ||
      xr + r >= right.cols) {
    return 2.0;
  }
  cv::Mat1d a, b;
  left(cv::Rect(x - r, y - r, 2 * r + 1, 2 * r + 1)).convertTo(a, CV_64F);
  right(cv::Rect(xr - r, y - r, 2 * r + 1, 2 * r + 1)).convertTo(b, CV_64F);
  a -= cv::mean(a)[0];
  b -= cv::mean(b)[0];
  const double den = std::sqrt(a.dot(a) * b.dot(b));
  return den > 1e-9 ? 1.0 - a.dot(b) / den : 2.0;
}

/// A fed point within neighbour_cols columns, in rows [y_lo, y_hi], at depth z within the
/// tolerance.
bool lidarShowsSurface(const cv::Mat1f& fed, int x, int y_lo, int y_hi, double z, double fb,
                       const TopBandParams& p) {
  for (int u = std::max(0, x - p.neighbour_cols); u <= std::min(fed.cols - 1, x + p.neighbour_cols);
       ++u) {
    for (int v = std::max(0, y_lo); v <= std::min(fed.rows - 1, y_hi); ++v) {
      const float d = fed(v, u);
      if (d > 0.f && std::abs(fb / d - z) <= p.depth_tolerance * z) return true;
    }
  }
  return false;
}

}  // namespace

TopBandReport checkTopBand(const cv::Mat1f& fed, const cv::Mat1f& disparity, const cv::Mat& left,
                           const cv::Mat& right, const StereoCamera& camera,
                           const TopBandParams& params) {
  if (fed.empty() || disparity.empty() || left.empty() || right.empty()) {
    throw std::invalid_argument("checkTopBand: an input is empty");
  }
  if (fed.size() != disparity.size() || left.size() != fed.size() || right.size() != fed.size()) {
    throw std::invalid_argument("checkTopBand: the maps and images differ in size");
  }
  const double fb = camera.fx * camera.baseline;
  const cv::Mat1b grey_left = toGrey(left), grey_right = toGrey(right);
  TopBandReport report;
  for (int x = 0; x < fed.cols; ++x) {
    int top = 0;
    while (top < fed.rows && !(fed(top, x) > 0.f)) ++top;
    if (top == fed.rows) continue;
    const double z_top = fb / fed(top, x);
    if (z_top <= params.min_depth) continue;
    int y_band = -1;  // the nearest output in the rows above the top point
    for (int y = std::max(0, top - params.rows); y < top; ++y) {
      const float d = disparity(y, x);
      if (d > 0.f && std::isfinite(d) && (y_band < 0 || d > disparity(y_band, x))) y_band = y;
    }
    if (y_band < 0) continue;
    ++report.columns;
    const double z_band = fb / disparity(y_band, x);
    if (z_band >= params.ratio * z_top) continue;
    const bool images =
        nccCost(grey_left, grey_right, x, y_band, disparity(y_band, x)) + params.ncc_margin <
        nccCost(grey_left, grey_right, x, y_band, fed(top, x));
    if (images || lidarShowsSurface(fed, x, y_band - params.rows, top + 2, z_band, fb, params)) {
      ++report.excused;
    } else {
      ++report.banded;
    }
  }
  return report;
}

}  // namespace lidar_stereo_fusion
