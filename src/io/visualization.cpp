// Colourised disparity / depth / error maps (OpenCV's perceptual TURBO colour map).
#include "lidar_stereo_fusion/io/visualization.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace lidar_stereo_fusion {
namespace {

bool hasValue(float v) { return std::isfinite(v) && v > 0.f; }

/// Largest valid value of `m` (0 when there is none).
double maxValue(const cv::Mat1f& m) {
  double best = 0.0;
  for (int y = 0; y < m.rows; ++y) {
    for (int x = 0; x < m.cols; ++x) {
      if (hasValue(m(y, x))) best = std::max(best, static_cast<double>(m(y, x)));
    }
  }
  return best;
}

/// Maps `level` (0..255) through TURBO; pixels where `mask` is 0 become black.
cv::Mat colorize(const cv::Mat1b& level, const cv::Mat1b& mask) {
  cv::Mat color;
  cv::applyColorMap(level, color, cv::COLORMAP_TURBO);
  color.setTo(cv::Scalar::all(0), mask == 0);
  return color;
}

uint8_t toLevel(double fraction) {
  return static_cast<uint8_t>(std::lround(255.0 * std::clamp(fraction, 0.0, 1.0)));
}

void requireNonEmpty(const cv::Mat& m, const char* who) {
  if (m.empty()) throw std::invalid_argument(std::string(who) + ": empty input");
}

}  // namespace

cv::Mat colorizeDisparity(const cv::Mat1f& disparity, double max_disparity) {
  requireNonEmpty(disparity, "colorizeDisparity");
  const double scale = max_disparity > 0 ? max_disparity : maxValue(disparity);
  cv::Mat1b level(disparity.size(), uint8_t{0}), mask(disparity.size(), uint8_t{0});
  for (int y = 0; y < disparity.rows; ++y) {
    for (int x = 0; x < disparity.cols; ++x) {
      const float d = disparity(y, x);
      if (!hasValue(d)) continue;
      mask(y, x) = 255;
      level(y, x) = toLevel(scale > 0 ? d / scale : 0.0);
    }
  }
  return colorize(level, mask);
}

cv::Mat colorizeConfidence(const cv::Mat1f& confidence, const cv::Mat1f& prior) {
  requireNonEmpty(confidence, "colorizeConfidence");
  if (prior.size() != confidence.size()) {
    throw std::invalid_argument("colorizeConfidence: prior and confidence differ in size");
  }
  cv::Mat1b level(confidence.size(), uint8_t{0});
  for (int y = 0; y < confidence.rows; ++y) {
    for (int x = 0; x < confidence.cols; ++x) level(y, x) = toLevel(confidence(y, x));
  }
  cv::Mat color;
  cv::applyColorMap(level, color, cv::COLORMAP_VIRIDIS);
  color.setTo(cv::Scalar::all(0), ~(prior > 0.f));
  return color;
}

cv::Mat colorizeDepth(const cv::Mat1f& depth, double max_depth) {
  requireNonEmpty(depth, "colorizeDepth");
  if (!(max_depth > 0)) throw std::invalid_argument("colorizeDepth: max_depth must be > 0 [m]");
  cv::Mat1b level(depth.size(), uint8_t{0}), mask(depth.size(), uint8_t{0});
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) {
      const float z = depth(y, x);
      if (!hasValue(z)) continue;
      mask(y, x) = 255;
      level(y, x) = toLevel(1.0 - z / max_depth);  // near = warm (high end of TURBO)
    }
  }
  return colorize(level, mask);
}

cv::Mat colorizeError(const cv::Mat1f& estimate, const cv::Mat1f& reference, double max_error) {
  requireNonEmpty(reference, "colorizeError");
  if (estimate.size() != reference.size()) {
    throw std::invalid_argument("colorizeError: estimate and reference differ in size");
  }
  if (!(max_error > 0)) throw std::invalid_argument("colorizeError: max_error must be > 0");
  cv::Mat1b level(reference.size(), uint8_t{0}), mask(reference.size(), uint8_t{0});
  for (int y = 0; y < reference.rows; ++y) {
    for (int x = 0; x < reference.cols; ++x) {
      const float ref = reference(y, x);
      if (!hasValue(ref)) continue;
      const float est = estimate(y, x);
      const double err = hasValue(est) ? std::abs(est - ref) : max_error;  // missing: worst
      mask(y, x) = 255;
      level(y, x) = toLevel(err / max_error);
    }
  }
  return colorize(level, mask);
}

cv::Mat withColorBar(const cv::Mat& picture, double value_at_0, double value_at_255,
                     const std::string& unit, int colormap) {
  requireNonEmpty(picture, "withColorBar");
  if (picture.type() != CV_8UC3) throw std::invalid_argument("withColorBar: picture must be BGR8");
  // Sized for the picture: readable on a 1242-wide KITTI frame and on a 320-wide test image.
  const int width = picture.cols, margin = std::max(8, width / 40);
  const double font = std::clamp(width / 1400.0, 0.3, 0.8);
  const int bar_height = std::max(8, width / 60), text_height = static_cast<int>(28 * font) + 6;
  cv::Mat out(picture.rows + bar_height + text_height + 6, width, CV_8UC3, cv::Scalar::all(0));
  picture.copyTo(out(cv::Rect(0, 0, width, picture.rows)));
  const int bar_width = width - 2 * margin, top = picture.rows + 3;
  if (bar_width < 2) return out;
  cv::Mat1b levels(1, bar_width);
  for (int x = 0; x < bar_width; ++x) levels(0, x) = toLevel(x / (bar_width - 1.0));
  cv::Mat bar;
  cv::applyColorMap(levels, bar, colormap);
  cv::resize(bar, bar, cv::Size(bar_width, bar_height), 0, 0, cv::INTER_NEAREST);
  bar.copyTo(out(cv::Rect(margin, top, bar_width, bar_height)));
  for (int k = 0; k <= 4; ++k) {
    const double f = k / 4.0, value = value_at_0 + f * (value_at_255 - value_at_0);
    char text[64];
    std::snprintf(text, sizeof(text), "%.3g%s%s", value, unit.empty() ? "" : " ", unit.c_str());
    int baseline = 0;
    const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, font, 1, &baseline);
    const int x = std::clamp(margin + static_cast<int>(f * (bar_width - 1)) - size.width / 2, 0,
                             std::max(0, width - size.width));
    cv::putText(out, text, cv::Point(x, top + bar_height + size.height + 3),
                cv::FONT_HERSHEY_SIMPLEX, font, cv::Scalar::all(230), 1, cv::LINE_AA);
  }
  return out;
}

double disparityColorScale(const cv::Mat1f& disparity, double max_search) {
  std::vector<float> values;
  values.reserve(disparity.total());
  for (const float d : disparity) {
    if (d > 0.f) values.push_back(d);
  }
  double top = 16.0;
  if (!values.empty()) {
    auto at = values.begin() + static_cast<std::ptrdiff_t>(0.99 * (values.size() - 1));
    std::nth_element(values.begin(), at, values.end());
    top = 16.0 * std::max(1.0, std::ceil(*at / 16.0));
  }
  return std::min(max_search, top);
}

cv::Mat disparityPicture(const cv::Mat1f& disparity, double max_search) {
  const double max = disparityColorScale(disparity, max_search);
  return withColorBar(colorizeDisparity(disparity, max), 0.0, max, "px");
}

cv::Mat depthPicture(const cv::Mat1f& depth, double max_depth) {
  return withColorBar(colorizeDepth(depth, max_depth), max_depth, 0.0, "m");
}

cv::Mat overlaySparse(const cv::Mat& image, const cv::Mat1f& sparse, double max_disparity) {
  requireNonEmpty(image, "overlaySparse");
  if (image.size() != sparse.size()) {
    throw std::invalid_argument("overlaySparse: image and sparse disparity differ in size");
  }
  if (image.type() != CV_8UC3 && image.type() != CV_8UC1) {
    throw std::invalid_argument("overlaySparse: image must be BGR CV_8UC3 or grey CV_8UC1");
  }
  cv::Mat canvas;
  if (image.channels() == 1) {
    cv::cvtColor(image, canvas, cv::COLOR_GRAY2BGR);
  } else {
    canvas = image.clone();
  }
  canvas.convertTo(canvas, -1, 0.4);  // darken so the dots stand out
  const cv::Mat colors = colorizeDisparity(sparse, max_disparity);
  for (int y = 0; y < sparse.rows; ++y) {
    for (int x = 0; x < sparse.cols; ++x) {
      if (!hasValue(sparse(y, x))) continue;
      const cv::Vec3b c = colors.at<cv::Vec3b>(y, x);
      cv::circle(canvas, cv::Point(x, y), 1, cv::Scalar(c[0], c[1], c[2]), cv::FILLED);
    }
  }
  return canvas;
}

}  // namespace lidar_stereo_fusion
