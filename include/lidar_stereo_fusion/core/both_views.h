// Runs a stereo pair's two independent per-view steps side by side (core-internal helper).
#pragma once

#include <future>

namespace lidar_stereo_fusion {

/// Runs `left` and `right`, the right one beside the left when more than one thread may run.
/// Exceptions of either reach the caller: the right one's through the future, whose destructor
/// waits for it if the left one throws.
template <class Left, class Right>
void bothViews(int threads, Left&& left, Right&& right) {
  std::future<void> right_done;
  if (threads > 1) {
    right_done = std::async(std::launch::async, right);
  } else {
    right();
  }
  left();
  if (right_done.valid()) right_done.get();
}

}  // namespace lidar_stereo_fusion
