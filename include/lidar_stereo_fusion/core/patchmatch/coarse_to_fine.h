// PatchMatch coarse start: the search for the region the LiDAR does not settle (no prior, edges,
// holes) first runs on images reduced by coarse_scale, where a window covers coarse_scale^2 times
// the area for the same number of samples and the disparity range is coarse_scale times shorter;
// at full size, `fine_iterations` sweeps refine its planes locally. Not in the paper (a common
// PatchMatch acceleration); coarse_scale = 1 turns it off.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/patchmatch/params.h"
#include "lidar_stereo_fusion/core/patchmatch/plane.h"

namespace lidar_stereo_fusion {
namespace patchmatch {

/// A view's input reduced by `scale`: images by area averaging, prior, confidence and bounds by
/// nearest neighbour with disparities divided by `scale`.
ViewInput downsampleView(const ViewInput& in, int scale);
/// The same into `out`, reusing its buffers where they have the size.
void downsampleView(const ViewInput& in, int scale, ViewInput& out);

/// Parameters of the coarse level: window radius and stride, disparity range and refinement floor
/// divided by coarse_scale (at least 1 / a positive range), no left-right check, no coarse start.
PatchMatchParams coarseParams(const PatchMatchParams& p);

/// The full-size plane of coarse plane q = (a, b, c) (upsamplePlanes).
inline Plane upsampledPlane(const cv::Vec3f& q, float scale) {
  const float offset = 0.5f * (scale - 1.f);
  return Plane{q[0], q[1], scale * q[2] - offset * (q[0] + q[1])};
}

/// Full-size planes from the coarse level's plane map (a, b, c) per coarse pixel: pixel (x, y)
/// takes the plane of coarse pixel (x / scale, y / scale), which at full size (coarse pixel
/// centres at full-size coordinate i scale + (scale - 1) / 2) is
/// d = a x + b y + scale c - (a + b) (scale - 1) / 2. Rows run on `threads` threads.
std::vector<Plane> upsamplePlanes(const cv::Mat3f& coarse, int scale, const cv::Size& full,
                                  int threads = 1);

/// Full-size mask from a coarse level's mask: pixel (x, y) takes coarse pixel (x / scale,
/// y / scale), as upsamplePlanes.
cv::Mat1b upsampleMask(const cv::Mat1b& coarse, int scale, const cv::Size& full);

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
