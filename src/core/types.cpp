// StereoCamera validation: the one place that decides which camera values are impossible.
#include "lidar_stereo_fusion/core/types.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace lidar_stereo_fusion {

namespace {

void requirePositive(double value, const char* name, const char* unit) {
  if (!std::isfinite(value) || value <= 0.0) {
    throw std::invalid_argument(std::string("StereoCamera: ") + name + " must be finite and > 0 " +
                                unit + ", got " + std::to_string(value));
  }
}

void requireFinite(double value, const char* name) {
  if (!std::isfinite(value)) {
    throw std::invalid_argument(std::string("StereoCamera: ") + name + " must be finite, got " +
                                std::to_string(value));
  }
}

}  // namespace

void StereoCamera::validate() const {
  requirePositive(fx, "fx", "[px]");
  requirePositive(fy, "fy", "[px]");
  requireFinite(cx, "cx");
  requireFinite(cy, "cy");
  requirePositive(baseline, "baseline", "[m]");
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument("StereoCamera: image size must be positive, got " +
                                std::to_string(width) + "x" + std::to_string(height));
  }
}

std::string baselinePlausibilityProblem(double baseline) {
  if (baseline >= kMinPlausibleBaseline && baseline <= kMaxPlausibleBaseline) return {};
  std::string text = "baseline " + std::to_string(baseline) +
                     " m is outside the plausible range [" + std::to_string(kMinPlausibleBaseline) +
                     ", " + std::to_string(kMaxPlausibleBaseline) + "] m";
  if (baseline > kMaxPlausibleBaseline && baseline / 1000.0 <= kMaxPlausibleBaseline) {
    text += ": is the projection matrix in millimetres? Then the baseline is " +
            std::to_string(baseline / 1000.0) + " m (Tx = P[3] = -fx * baseline, baseline in m)";
  } else {
    text += " (Tx = P[3] = -fx * baseline, baseline in m)";
  }
  return text;
}

}  // namespace lidar_stereo_fusion
