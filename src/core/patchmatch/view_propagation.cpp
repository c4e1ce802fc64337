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

void offerView(const ViewState& src, const PlaneSearch& dst_search, ViewState& dst,
               const PatchMatchParams& p, bool left_to_right) {
#pragma omp parallel for schedule(static) num_threads(threadCount(p))
  for (int y = 0; y < src.height; ++y) {
    const float fy = static_cast<float>(y);
    // Source pixels in the order in which a nearer surface comes after a farther one that maps
    // to the same pixel (left -> right: increasing x; right -> left: decreasing x), so that the
    // last offer made to a pixel is the surface its view sees.
    for (int i = 0; i < src.width; ++i) {
      const int x = left_to_right ? i : src.width - 1 - i;
      const Plane& plane = src.planes[y * src.width + x];
      const float d = plane.at(static_cast<float>(x), fy);
      const int xq = static_cast<int>(std::lround(x + src.match_sign * d));
      if (xq < 0 || xq >= dst.width) continue;
      const int idx = y * dst.width + xq;
      if (dst.isLocked(idx)) continue;
      const Plane moved = transferPlane(plane, left_to_right);
      const float fxq = static_cast<float>(xq);
      if (nearlySame(dst.planes[idx], moved, fxq, fy)) continue;
      if (!dst_search.admissible(xq, y, moved.at(fxq, fy))) continue;
      dst.offer[idx] = moved;
      dst.offered[idx] = 1;
    }
  }
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
