// The core's threads: a process-wide pool of workers that never makes a caller wait for a thread
// that has not started. OpenMP's fork and join (and std::async's thread per call) make every
// parallel step wait at its end for each thread of its team, even one the operating system has
// not run yet: on a host whose cores are busy with other processes (a ROS graph, a bag player) a
// step of 0.1 ms then took a scheduler's time slice, several ms, and two threads were slower than
// one. Here the caller works through the items itself from the first; a worker takes the next
// item when it runs, and the caller waits at the end only for items a worker has taken and not
// finished. Which thread runs an item never changes a result.
#pragma once

#include <functional>

namespace lidar_stereo_fusion {
namespace patchmatch {

/// Runs body(i) for every i in [0, n) on the calling thread and at most threads - 1 workers, the
/// items handed out in increasing order, and returns when all are done. Runs them all on the
/// calling thread when threads <= 1, and when the pool is busy (a call from inside an item, or
/// from another thread at the same time). body must not throw.
void parallelFor(int n, int threads, const std::function<void(int)>& body);

/// parallelFor over the rows [0, rows) in chunks of about rows / (4 threads) rows (at least
/// `min_chunk`): body(y0, y1) for each chunk [y0, y1).
void parallelRows(int rows, int threads, const std::function<void(int, int)>& body,
                  int min_chunk = 4);

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
