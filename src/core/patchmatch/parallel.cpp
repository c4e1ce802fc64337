// The core's threads (parallel.h). A job is the body, the number of items and two counters; the
// workers sleep on a condition variable between jobs (after a short spin, so that the steps of a
// frame, one after the other, find them awake).
#include "lidar_stereo_fusion/core/patchmatch/parallel.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "lidar_stereo_fusion/core/patchmatch.h"

namespace lidar_stereo_fusion {
namespace patchmatch {

namespace {

struct Job {
  const std::function<void(int)>* body = nullptr;
  int n = 0;
  int helpers_wanted = 0;
  std::atomic<int> next{0}, done{0}, helpers{0};
  std::mutex mutex;
  std::condition_variable finished;

  /// Takes items until none is left; wakes the caller when the last one is done.
  void work() {
    for (int i = next.fetch_add(1); i < n; i = next.fetch_add(1)) {
      (*body)(i);
      if (done.fetch_add(1) + 1 == n) {
        std::lock_guard<std::mutex> lock(mutex);
        finished.notify_all();
      }
    }
  }

  /// Waits until every item is done (items taken by a worker that has not finished them).
  void wait() {
    const auto spin_until = std::chrono::steady_clock::now() + std::chrono::microseconds(50);
    while (done.load() < n && std::chrono::steady_clock::now() < spin_until) {
      std::this_thread::yield();
    }
    std::unique_lock<std::mutex> lock(mutex);
    finished.wait(lock, [&] { return done.load() == n; });
  }
};

class Pool {
 public:
  ~Pool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : workers_) t.join();
  }

  /// Runs the job with up to threads - 1 workers; false (nothing run) when the pool is busy.
  bool run(int n, int threads, const std::function<void(int)>& body) {
    if (busy_.exchange(true)) return false;
    const auto job = std::make_shared<Job>();
    job->body = &body;
    job->n = n;
    job->helpers_wanted = std::min(threads, n) - 1;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      while (static_cast<int>(workers_.size()) < job->helpers_wanted) {
        workers_.emplace_back([this] { serve(); });
      }
      job_ = job;
      published_.fetch_add(1);
    }
    wake_.notify_all();
    job->work();
    job->wait();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_.reset();
    }
    busy_.store(false);
    return true;
  }

 private:
  /// A worker: takes part in each new job (if the job still wants a helper) until the pool ends.
  void serve() {
    unsigned long seen = 0;
    for (;;) {
      // A short spin first: the next step of the frame usually follows within microseconds.
      const auto spin_until = std::chrono::steady_clock::now() + std::chrono::microseconds(100);
      while (published_.load() == seen && std::chrono::steady_clock::now() < spin_until) {
        std::this_thread::yield();
      }
      std::shared_ptr<Job> job;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || published_.load() != seen; });
        if (stop_) return;
        seen = published_.load();
        job = job_;
      }
      if (job && job->helpers.fetch_add(1) < job->helpers_wanted) job->work();
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  std::vector<std::thread> workers_;
  std::shared_ptr<Job> job_;
  std::atomic<unsigned long> published_{0};
  std::atomic<bool> busy_{false};
  bool stop_ = false;
};

Pool& pool() {
  static Pool instance;
  return instance;
}

}  // namespace

void parallelFor(int n, int threads, const std::function<void(int)>& body) {
  threads = std::min(threads, PatchMatchParams::kMaxThreads);
  if (threads > 1 && n > 1 && pool().run(n, threads, body)) return;
  for (int i = 0; i < n; ++i) body(i);
}

void parallelRows(int rows, int threads, const std::function<void(int, int)>& body, int min_chunk) {
  const int chunk = std::max(min_chunk, rows / std::max(1, 4 * threads));
  const int chunks = (rows + chunk - 1) / chunk;
  parallelFor(chunks, threads, [&](int i) { body(i * chunk, std::min(rows, (i + 1) * chunk)); });
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
