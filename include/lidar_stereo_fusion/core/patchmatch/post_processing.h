// PatchMatch post-processing (Bleyer et al. 2011): left-right consistency check, filling of the
// inconsistent pixels and a colour-weighted median over the filled ones. Private to the core;
// exposed for the per-step tests.
#pragma once

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/patchmatch/simd.h"
#include "lidar_stereo_fusion/core/patchmatch/view_state.h"

namespace lidar_stereo_fusion {
namespace patchmatch {

/// Disparity of every pixel's plane at the pixel [px].
/// Rows run on `threads` threads.
cv::Mat1f disparityOf(const ViewState& v, int threads = 1);

/// Left-right check: 255 where the left disparity and the right disparity at its match
/// (x - round(d)) differ by more than max_diff [px]. A pixel whose match falls outside the right
/// image (the left border strip) cannot be checked: it is kept (0), or marked 255 when
/// `unmatched_bad` (the fused method: stereo cannot see there, the LiDAR fill can). Pixels in
/// `keep` (locked pixels, which the LiDAR measured; may be empty()) are always kept.
cv::Mat1b leftRightCheck(const cv::Mat1f& left, const cv::Mat1f& right, float max_diff,
                         const std::vector<uint8_t>& keep, bool unmatched_bad = false,
                         int threads = 1);

/// The result of a level that does not search (PatchMatchParams::search_scale) from the level
/// below's, `scale` times smaller: each pixel's plane is the prior's where `v` locks it to the
/// prior (priorPlane), else the level below's up-sampled (upsampledPlane), and its disparity the
/// plane's; with `lr_check`, the pixels the level below's check marks (not those locked) are
/// marked in `inconsistent` and filled: by the prior where it has a value and its trust is >=
/// fill_trust (as fillHoles), else by `scale` times the level below's filled disparity at (x /
/// scale, y / scale). Non-positive or non-finite disparities become 0 (empty). The plane map
/// only with `planes`.
PatchMatchResult resultFromLevelBelow(const ViewState& v, const PatchMatchResult& below, int scale,
                                      bool lr_check, float fill_trust, bool planes = true,
                                      int threads = 1);

/// How fillHoles fills (PatchMatchParams' median_radius, weight_delta, fill_confidence,
/// max_disparity and simd_path).
struct FillOptions {
  int radius;           ///< half window of the weighted median [px]
  float delta;          ///< its colour weights exp(-L1 colour / delta)
  float fill_trust;     ///< the prior fills where its trust is >= this
  float max_disparity;  ///< the search range [px]: no fill above it
  SimdPath simd;        ///< the median kernel's instructions (same result on every path)
};

/// Fills the pixels marked in `bad` (modified), in three steps. Where the view's prior has a value
/// and its trust is >= fill_trust, the prior fills the hole (the LiDAR saw the point: our reading
/// for the fused method; Bleyer's background fill assumes no other source). Elsewhere the lower
/// (background) disparity of the nearest consistent planes left and right (of those not above
/// max_disparity, the configured search range, at the pixel), then a colour-weighted median over
/// the window of radius `radius` (every second row and column; weights exp(-L1 colour / delta)).
void fillHoles(const ViewState& v, cv::Mat1b bad, const FillOptions& options, cv::Mat1f& disparity,
               int threads);

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
