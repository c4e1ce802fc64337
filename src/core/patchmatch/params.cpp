// PatchMatch: the parameters' checks (PatchMatchParams::validate, patchmatch.h).
#include <cmath>
#include <stdexcept>
#include <string>

#include "lidar_stereo_fusion/core/patchmatch.h"

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
  require(window_radius >= 1 && window_radius <= 50, "window_radius must be in [1, 50]");
  require(window_stride >= 1 && window_stride <= window_radius,
          "window_stride must be in [1, window_radius]");
  require(weight_delta > 0, "weight_delta must be > 0");
  require(std::isfinite(image_smoothing) && image_smoothing >= 0 && image_smoothing <= 5,
          "image_smoothing must be in [0, 5] px");
  require(alpha >= 0 && beta >= 0 && gamma >= 0, "alpha, beta, gamma must be >= 0");
  require(std::abs(alpha + beta + gamma - 1.0) < 1e-6, "alpha + beta + gamma must be 1");
  require(!confidence_weighting || alpha + beta > 0,
          "confidence_weighting needs an image term (alpha + beta > 0)");
  require(lambda_col > 0 && lambda_grad > 0 && lambda_disp > 0, "truncations must be > 0");
  require(iterations >= 0 && iterations <= 100, "iterations must be in [0, 100]");
  require(right_iterations == -1 || right_iterations >= 1,
          "right_iterations must be -1 (every iteration) or >= 1");
  require(bound_margin >= 0, "bound_margin must be >= 0");
  require(min_refine_range >= 0, "min_refine_range must be >= 0");
  require(min_disparity > 0, "min_disparity must be > 0");
  require(max_disparity > min_disparity, "max_disparity must be > min_disparity");
  require(lr_max_diff > 0, "lr_max_diff must be > 0");
  require(median_radius >= 1 && median_radius <= 50, "median_radius must be in [1, 50]");
  require(std::isfinite(lock_confidence) && lock_confidence >= 0,
          "lock_confidence must be >= 0 (> 1 = never lock)");
  require(fill_confidence >= 0 && fill_confidence <= 1, "fill_confidence must be in [0, 1]");
  require(coarse_scale >= 1 && coarse_scale <= 16, "coarse_scale must be in [1, 16] (1 = off)");
  require(coarse_levels >= 1 && coarse_levels <= 4, "coarse_levels must be in [1, 4]");
  require(isLevelScale(*this, search_scale),
          "search_scale must be 1 or coarse_scale^k, k = 1 .. coarse_levels (a level's "
          "reduction factor)");
  require(isLevelScale(*this, unbounded_scale),
          "unbounded_scale must be 1 or coarse_scale^k, k = 1 .. coarse_levels (a level's "
          "reduction factor)");
  require(fine_iterations >= 1 && fine_iterations <= 100, "fine_iterations must be in [1, 100]");
  require(std::isfinite(fine_refine_range) && fine_refine_range > 0,
          "fine_refine_range must be > 0");
  require(num_threads >= 0 && num_threads <= 256,
          "num_threads must be in [0, 256] (0 = all cores)");
  require(simdPathSupported(simd_path), std::string("simd_path ") + simdPathName(simd_path) +
                                            ": this CPU (or build) does not run it");
}

}  // namespace lidar_stereo_fusion
