// Runs a stereo pair's two independent per-view steps side by side (core-internal helper).
#pragma once

#include <exception>

#include "lidar_stereo_fusion/core/patchmatch/parallel.h"

namespace lidar_stereo_fusion {

/// Runs `left` and `right`, the right one beside the left when more than one thread may run (on
/// the core's pool, patchmatch/parallel.h: the caller does both if no worker comes; on one thread
/// the right one first, as before the pool: the left view's stage 2 then ran 2.5 ms faster,
/// its inputs still in the cache). Exceptions of either reach the caller, the left one's first,
/// once both have ended.
template <class Left, class Right>
void bothViews(int threads, Left&& left, Right&& right) {
  std::exception_ptr failed[2];
  patchmatch::parallelFor(2, threads, [&](int i) {
    try {
      if (i == 0) {
        right();
      } else {
        left();
      }
    } catch (...) {
      failed[1 - i] = std::current_exception();  // failed[0]: the left one's
    }
  });
  for (const std::exception_ptr& e : failed) {
    if (e) std::rethrow_exception(e);
  }
}

}  // namespace lidar_stereo_fusion
