// Helpers of the step-by-step PatchMatch tests (test_patchmatch_steps.cpp,
// test_patchmatch_levels.cpp, test_patchmatch_post_processing.cpp): small views and parameters
// with exact answers.
#pragma once

#include <limits>

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/patchmatch/cost.h"
#include "lidar_stereo_fusion/core/patchmatch/propagation.h"
#include "lidar_stereo_fusion/core/patchmatch/view_state.h"

namespace lidar_stereo_fusion {
namespace test {

namespace pm = lidar_stereo_fusion::patchmatch;

/// Uniform images: every support weight is 1 and every gradient 0.
inline cv::Mat uniform(int w, int h, uchar value) {
  return cv::Mat(h, w, CV_8UC3, cv::Scalar::all(value));
}

inline lidar_stereo_fusion::PatchMatchParams params3x3() {
  lidar_stereo_fusion::PatchMatchParams p;  // defaults: alpha 0.01, beta 0.09, gamma 0.9, weighted
  p.window_radius = 1;
  p.window_stride = 1;
  p.window_round = false;  // the whole 3x3 square: 9 samples
  p.coarse_scale = 1;
  return p;
}

struct Views {
  pm::ViewState left, right;
};

/// A view searched by propagation alone (no plane refinement).
inline pm::SearchOptions propagationOnly() {
  pm::SearchOptions o;
  o.refine = false;
  return o;
}

inline Views prepare(const lidar_stereo_fusion::ViewInput& l,
                     const lidar_stereo_fusion::ViewInput& r,
                     const lidar_stereo_fusion::PatchMatchParams& p) {
  Views v;
  pm::prepareView(l, p, -1.f, v.left);
  pm::prepareView(r, p, +1.f, v.right);
  return v;
}

/// Front-parallel planes d = own at pixel idx (cost unknown), d = left at its left neighbour and
/// d = up at its upper neighbour (the candidates of a forward sweep's propagation).
inline void frontoParallelAround(pm::ViewState& v, int idx, float own, float left, float up) {
  v.planes[idx] = pm::Plane{0.f, 0.f, own};
  v.cost[idx] = pm::kUnknownCost;
  v.planes[idx - 1] = pm::Plane{0.f, 0.f, left};
  v.planes[idx - v.width] = pm::Plane{0.f, 0.f, up};
}

inline float costOf(const pm::MatchingCost& cost, int x, int y, const pm::Plane& plane) {
  pm::WindowCache cache;
  cost.buildWindow(x, y, cache);
  return cost.aggregate(cache, plane, std::numeric_limits<float>::max());
}

}  // namespace test
}  // namespace lidar_stereo_fusion
