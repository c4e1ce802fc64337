// PatchMatch: the parameters' checks (PatchMatchParams::validate, patchmatch/params.h).
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "lidar_stereo_fusion/core/param_table.h"
#include "lidar_stereo_fusion/core/patchmatch/params.h"

namespace lidar_stereo_fusion {

namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("PatchMatchParams: " + message);
}

/// Whether `s` is the reduction factor of a level of the coarse start: 1 or coarse_scale^k,
/// k = 1 .. coarse_levels.
bool isLevelScale(const PatchMatchParams& p, int s) {
  if (s == 1) return true;
  if (p.coarse_scale < 2) return false;
  for (int k = 1, f = p.coarse_scale; k <= p.coarse_levels; ++k, f *= p.coarse_scale) {
    if (s == f) return true;
  }
  return false;
}

}  // namespace

void PatchMatchParams::validate() const {
  requireRanges("PatchMatchParams", *this);
  // Checks between parameters (the table holds each one's own range).
  require(window_stride <= window_radius, "window_stride must be <= window_radius (" +
                                              std::to_string(window_radius) + "), got " +
                                              std::to_string(window_stride));
  require(std::abs(alpha + beta + gamma - 1.0) < 1e-6, "alpha + beta + gamma must be 1");
  require(!confidence_weighting || alpha + beta > 0,
          "confidence_weighting needs an image term (alpha + beta > 0)");
  require(output_median == 0 || output_median == 3 || output_median == 5,
          "output_median must be 0, 3 or 5, got " + std::to_string(output_median));
  require(right_iterations != 0, "right_iterations must be -1 (every iteration) or >= 1, got 0");
  require(max_disparity > min_disparity, "max_disparity must be > min_disparity");
  require(isLevelScale(*this, search_scale),
          "search_scale must be 1 or coarse_scale^k, k = 1 .. coarse_levels (a level's "
          "reduction factor)");
  require(isLevelScale(*this, unbounded_scale),
          "unbounded_scale must be 1 or coarse_scale^k, k = 1 .. coarse_levels (a level's "
          "reduction factor)");
  require(simdPathSupported(simd_path), std::string("simd_path ") + simdPathName(simd_path) +
                                            ": this CPU (or build) does not run it");
}

PatchMatchParams PatchMatchParams::forImage(int width, int height) const {
  PatchMatchParams p = *this;
  if (full_search_pixels > 0 &&
      static_cast<int64_t>(width) * height <= static_cast<int64_t>(full_search_pixels)) {
    p.search_scale = 1;
    p.intermediate_refine = true;
  }
  return p;
}

}  // namespace lidar_stereo_fusion
