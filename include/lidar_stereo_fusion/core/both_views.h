// Runs a stereo pair's two independent per-view steps side by side (core-internal helper).
#pragma once

#include <exception>

#include "lidar_stereo_fusion/core/patchmatch/parallel.h"

namespace lidar_stereo_fusion {

/// Runs `left` and `right`, the right one beside the left when more than one thread may run (on
/// the core's pool, patchmatch/parallel.h: the caller does both if no worker comes). Exceptions
/// of either reach the caller, the left one's first, once both have ended.
template <class Left, class Right>
void bothViews(int threads, Left&& left, Right&& right) {
  std::exception_ptr failed[2];
  patchmatch::parallelFor(2, threads, [&](int i) {
    try {
      if (i == 0) {
        left();
      } else {
        right();
      }
    } catch (...) {
      failed[i] = std::current_exception();
    }
  });
  for (const std::exception_ptr& e : failed) {
    if (e) std::rethrow_exception(e);
  }
}

}  // namespace lidar_stereo_fusion
