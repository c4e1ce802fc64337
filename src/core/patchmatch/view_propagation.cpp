// PatchMatch: view propagation (Bleyer et al.): a pixel's plane is offered to its match in the
// other view (propagation.h).
#include <cmath>

#include "lidar_stereo_fusion/core/patchmatch/propagation.h"

namespace lidar_stereo_fusion {
namespace patchmatch {

void propagateView(const ViewState& src, const PlaneSearch& dst_search, ViewState& dst,
                   const PatchMatchParams& p, bool left_to_right) {
#pragma omp parallel for schedule(dynamic, 4) num_threads(threadCount(p))
  for (int y = 0; y < src.height; ++y) {
    WindowCache cache;
    const float fy = static_cast<float>(y);
    for (int x = 0; x < src.width; ++x) {
      const Plane& plane = src.planes[y * src.width + x];
      const float d = plane.at(static_cast<float>(x), fy);
      const int xq = static_cast<int>(std::lround(x + src.match_sign * d));
      if (xq < 0 || xq >= dst.width) continue;
      const int idx = y * dst.width + xq;
      if (dst.isLocked(idx)) continue;
      const Plane moved = transferPlane(plane, left_to_right);
      Plane best = dst.planes[idx];
      const float fxq = static_cast<float>(xq);
      if (nearlySame(best, moved, fxq, fy)) continue;
      if (!dst_search.admissible(xq, y, moved.at(fxq, fy))) continue;
      dst_search.cost().buildWindow(xq, y, cache);
      float best_cost = dst_search.currentCost(idx, cache);
      dst_search.tryPlane(xq, y, moved, cache, best, best_cost);
      dst.planes[idx] = best;
      dst.cost[idx] = best_cost;
    }
  }
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
