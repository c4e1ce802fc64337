// Stage 3, last step: the output median (output_median.h).
#include "lidar_stereo_fusion/core/output_median.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

namespace lidar_stereo_fusion {

cv::Mat1f medianOfValues(const cv::Mat1f& disparity, int size) {
  if (size != 3 && size != 5) {
    throw std::invalid_argument("medianOfValues: size must be 3 or 5, got " + std::to_string(size));
  }
  if (disparity.empty()) throw std::invalid_argument("medianOfValues: empty disparity map");
  cv::Mat1f out;
  cv::medianBlur(disparity, out, size);  // OpenCV's SIMD median; right wherever nothing is empty
  const cv::Mat1b empty = ~(disparity > 0.f);
  if (cv::countNonZero(empty) == 0) return out;
  // Beside empty pixels: the median of the values alone, by hand (cv::medianBlur counts the
  // empty pixels' zeros as values).
  cv::Mat1b beside;
  cv::dilate(empty, beside, cv::Mat::ones(size, size, CV_8U));
  const int r = size / 2;
  std::array<float, 25> values;  // at most 5 x 5
  for (int y = 0; y < disparity.rows; ++y) {
    for (int x = 0; x < disparity.cols; ++x) {
      if (empty(y, x)) {
        out(y, x) = disparity(y, x);
        continue;
      }
      if (!beside(y, x)) continue;
      int n = 0;
      for (int dy = -r; dy <= r; ++dy) {
        const float* row = disparity[std::clamp(y + dy, 0, disparity.rows - 1)];
        for (int dx = -r; dx <= r; ++dx) {
          const float v = row[std::clamp(x + dx, 0, disparity.cols - 1)];
          if (v > 0.f) values[n++] = v;
        }
      }
      float* middle = values.data() + (n - 1) / 2;
      std::nth_element(values.data(), middle, values.data() + n);
      out(y, x) = *middle;
    }
  }
  return out;
}

cv::Mat1f measuredPoints(const cv::Mat1f& sparse, const cv::Mat1f& lines) {
  if (sparse.size() != lines.size()) {
    throw std::invalid_argument("measuredPoints: the projection and the scan lines differ in size");
  }
  cv::Mat1f out(sparse.size());
  for (int y = 0; y < sparse.rows; ++y) {
    const float* s = sparse[y];
    const float* l = lines[y];
    float* o = out[y];
    for (int x = 0; x < sparse.cols; ++x) o[x] = isMeasuredPoint(s[x], l[x]) ? s[x] : 0.f;
  }
  return out;
}

cv::Mat1f medianKeepingMeasured(const cv::Mat1f& disparity, int size, const cv::Mat1f& sparse,
                                const cv::Mat1f& lines, float tolerance) {
  if (sparse.size() != disparity.size() || lines.size() != disparity.size()) {
    throw std::invalid_argument(
        "medianKeepingMeasured: the projection or the scan lines differ in size from the "
        "disparity");
  }
  if (!(tolerance >= 0.f) || !std::isfinite(tolerance)) {
    throw std::invalid_argument("medianKeepingMeasured: tolerance must be finite and >= 0");
  }
  cv::Mat1f out = medianOfValues(disparity, size);
  // One pass over the three maps, no map of the measured points (the pipeline with it: within
  // 0.3 % of the plain median, doc/performance.md).
  for (int y = 0; y < disparity.rows; ++y) {
    const float* s = sparse[y];
    const float* l = lines[y];
    const float* d = disparity[y];
    float* o = out[y];
    for (int x = 0; x < disparity.cols; ++x) {
      if (keepsMeasuredPoint(d[x], s[x], l[x], tolerance)) o[x] = d[x];
    }
  }
  return out;
}

}  // namespace lidar_stereo_fusion
