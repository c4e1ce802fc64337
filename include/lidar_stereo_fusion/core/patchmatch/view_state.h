// PatchMatch: everything the search keeps about one view (images as float, prior, confidence,
// search bounds, the current plane and cost of every pixel). Private to the core; exposed for the
// per-step tests.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/patchmatch/cost_kernel.h"
#include "lidar_stereo_fusion/core/patchmatch/params.h"
#include "lidar_stereo_fusion/core/patchmatch/plane.h"

namespace lidar_stereo_fusion {
namespace patchmatch {

constexpr uint8_t kLockedToPrior = 1;
constexpr uint8_t kSettledByGuide = 2;
constexpr uint8_t kLeftToFill = 3;
constexpr uint8_t kKeptFromGuide = 4;

struct ViewState {
  int width = 0, height = 0;
  float match_sign = -1.f;  ///< the match of x is at x + sign * d in the other view
  cv::Mat3f color;          ///< BGR float, 0..255, after image_smoothing (the fill's weights)
  cv::Mat1f prior;          ///< up-sampled LiDAR disparity [px], 0 = empty (may be empty())
  /// Weight [0, 1] of the prior per pixel: the prior's confidence with confidence_weighting, else
  /// 1 where the prior has a value (the paper). Empty when there is no prior.
  cv::Mat1f trust;
  cv::Mat1f lo, hi, range;         ///< search bounds [px] (empty: unbounded)
  float d_min = 0.f, d_max = 0.f;  ///< the image's disparity range [px]
  std::vector<Plane> planes;
  std::vector<float> cost;
  /// Pixels that are not searched: kLockedToPrior where the plane is the prior's (trust >=
  /// lock_confidence), kSettledByGuide where it is the coarse level's (no scan-line bounds and
  /// full_size_unbounded false; polished), kKeptFromGuide where it is the coarse level's as it is
  /// (no scan-line bounds, at a level finer than unbounded_scale), kLeftToFill where the level
  /// below found the pixel inconsistent (leaveToFill); 0 elsewhere.
  std::vector<uint8_t> locked;
  /// Planes of the coarse start, up-sampled (empty: none): the initial plane where admissible.
  std::vector<Plane> guide;
  /// Planes handed over by view propagation before this view's sweep (offerView): `offer[i]` is
  /// tried when the sweep visits pixel i if `offered[i]`, then withdrawn.
  std::vector<Plane> offer;
  std::vector<uint8_t> offered;
  /// The colour and gradient as the cost reads them (both kernels): kTexelChannels per pixel,
  /// row-major (B, G, R, 0, gx, gy, 0, 0), 16-bit fixed point (cost_kernel.h).
  std::vector<Texel> texels;

  /// Whether (x, y) has scan-line bounds. Asked for every candidate plane: it tests the data
  /// pointer, as cv::Mat::empty() is a call into the library (lo is empty or full-size,
  /// checkViewInput).
  bool bounded(int x, int y) const { return lo.data != nullptr && hi(y, x) > 0.f; }
  bool isLocked(int idx) const { return locked[idx] != 0; }
};

/// Fills `v` from one view's input (reusing its buffers). match_sign: -1 left, +1 right.
void prepareView(const ViewInput& in, const PatchMatchParams& p, float match_sign, ViewState& v);

/// The part of prepareView that needs no image: size, prior, trust, bounds, the image's range and
/// the pixels locked to the prior (a level that does not search, PatchMatchParams::search_scale).
void preparePrior(const ViewInput& in, const PatchMatchParams& p, ViewState& v);

/// Sets the coarse level's planes as `v`'s guide and settles the pixels without scan-line bounds
/// that are not locked to the prior: at a level finer than unbounded_scale they keep the guide's
/// plane as it is (kKeptFromGuide); else, unless full_size_unbounded, they keep it polished
/// (kSettledByGuide).
void setGuide(std::vector<Plane> guide, const PatchMatchParams& p, ViewState& v);

/// Marks the pixels of the left view that are set in `inconsistent` (the level below's
/// left-right check, up-sampled; PatchMatchParams::skip_inconsistent), have no scan-line bounds
/// and are not locked to the prior, kLeftToFill: they are not searched, and each takes the plane
/// before it in the row, as the hole filling would (PlaneSearch::processPixel). Pixels between
/// scan lines are searched even then: their planes, bounded by the LiDAR, carry the propagation
/// along the row.
void leaveToFill(const cv::Mat1b& inconsistent, ViewState& v);

/// Throws std::invalid_argument naming the problem when a view's input does not fit `size`.
void checkViewInput(const ViewInput& v, const cv::Size& size, const char* which);

/// Slope (a, b) of the prior at (x, y) by central differences, when all four neighbours have a
/// value and |a|, |b| < 1 px/px (a surface, not a depth edge).
bool priorSlope(const ViewState& v, int x, int y, float& a, float& b);

/// The plane of a locked pixel: the prior's value at (x, y) and its slope per axis from central
/// differences, one-sided differences where one neighbour has no value (so that the plane of the
/// last scan line extrapolates the surface beyond it), 0 where none has or where the slope is
/// 1 px/px or more (a depth edge). Requires prior(y, x) > 0.
Plane priorPlane(const ViewState& v, int x, int y);

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
