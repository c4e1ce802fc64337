// PatchMatch: view propagation (Bleyer et al.): a pixel's plane is offered to its match in the
// other view (propagation.h).
#include <cmath>

#include "lidar_stereo_fusion/core/patchmatch/parallel.h"
#include "lidar_stereo_fusion/core/patchmatch/propagation.h"

namespace lidar_stereo_fusion {
namespace patchmatch {

namespace {

/// The index of the `dst` pixel that source pixel (x, y) matches, with the source plane
/// transferred into `dst` (moved), if that pixel may take it: inside the image, not locked, not
/// holding nearly that plane already, and the plane admissible there. Else -1.
int transferTarget(const ViewState& src, const PlaneSearch& dst_search, const ViewState& dst, int x,
                   int y, bool left_to_right, Plane& moved) {
  const Plane& plane = src.planes[y * src.width + x];
  const float fy = static_cast<float>(y);
  const int xq =
      static_cast<int>(std::lround(x + src.match_sign * plane.at(static_cast<float>(x), fy)));
  if (xq < 0 || xq >= dst.width) return -1;
  const int idx = y * dst.width + xq;
  if (dst.isLocked(idx)) return -1;
  moved = transferPlane(plane, left_to_right);
  const float fxq = static_cast<float>(xq);
  if (nearlySame(dst.planes[idx], moved, fxq, fy)) return -1;
  if (!dst_search.admissible(xq, y, moved.at(fxq, fy))) return -1;
  return idx;
}

}  // namespace

void propagateView(const ViewState& src, const PlaneSearch& dst_search, ViewState& dst,
                   const PatchMatchParams& p, bool left_to_right) {
  parallelRows(src.height, threadCount(p), [&](int y0, int y1) {
    WindowCache cache;
    for (int y = y0; y < y1; ++y) {
      for (int x = 0; x < src.width; ++x) {
        Plane moved;
        const int idx = transferTarget(src, dst_search, dst, x, y, left_to_right, moved);
        if (idx < 0) continue;
        const int xq = idx - y * dst.width;
        Plane best = dst.planes[idx];
        dst_search.cost().buildWindow(xq, y, cache);
        float best_cost = dst_search.currentCost(idx, cache);
        dst_search.tryPlane(xq, y, moved, cache, best, best_cost);
        dst.planes[idx] = best;
        dst.cost[idx] = best_cost;
      }
    }
  });
}

void offerView(const ViewState& src, const PlaneSearch& dst_search, ViewState& dst,
               const PatchMatchParams& p, bool left_to_right) {
  parallelRows(src.height, threadCount(p), [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      // Source pixels in the order in which a nearer surface comes after a farther one that maps
      // to the same pixel (left -> right: increasing x; right -> left: decreasing x), so that
      // the last offer made to a pixel is the surface its view sees.
      for (int i = 0; i < src.width; ++i) {
        const int x = left_to_right ? i : src.width - 1 - i;
        Plane moved;
        const int idx = transferTarget(src, dst_search, dst, x, y, left_to_right, moved);
        if (idx < 0) continue;
        dst.offer[idx] = moved;
        dst.offered[idx] = 1;
      }
    }
  });
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
