// The core's threads (patchmatch/parallel.h): every item runs exactly once, whatever the thread
// count, from inside an item (the pool then busy: the items run on the calling thread) and from
// two threads at once.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "lidar_stereo_fusion/core/patchmatch/parallel.h"

namespace pm = lidar_stereo_fusion::patchmatch;

TEST(Parallel, EveryItemRunsExactlyOnce) {
  for (const int threads : {1, 2, 3, 8}) {
    for (const int n : {0, 1, 2, 7, 64, 1000}) {
      std::vector<std::atomic<int>> runs(static_cast<size_t>(n));
      pm::parallelFor(n, threads, [&](int i) { runs[static_cast<size_t>(i)].fetch_add(1); });
      for (int i = 0; i < n; ++i) ASSERT_EQ(runs[i].load(), 1) << threads << " threads, item " << i;
    }
  }
}

TEST(Parallel, RowChunksCoverEveryRowOnce) {
  for (const int threads : {1, 2, 5}) {
    for (const int rows : {1, 3, 17, 375}) {
      std::vector<std::atomic<int>> runs(static_cast<size_t>(rows));
      pm::parallelRows(rows, threads, [&](int y0, int y1) {
        ASSERT_LT(y0, y1);
        for (int y = y0; y < y1; ++y) runs[static_cast<size_t>(y)].fetch_add(1);
      });
      for (int y = 0; y < rows; ++y)
        ASSERT_EQ(runs[y].load(), 1) << threads << " threads, row " << y;
    }
  }
}

TEST(Parallel, ACallFromAnItemOrAnotherThreadRunsAllItsItems) {
  std::atomic<int> inner{0};
  pm::parallelFor(4, 2, [&](int) { pm::parallelFor(10, 2, [&](int) { inner.fetch_add(1); }); });
  EXPECT_EQ(inner.load(), 40);
  std::atomic<int> a{0}, b{0};
  std::thread other([&] {
    for (int r = 0; r < 50; ++r) pm::parallelFor(20, 2, [&](int) { a.fetch_add(1); });
  });
  for (int r = 0; r < 50; ++r) pm::parallelFor(20, 2, [&](int) { b.fetch_add(1); });
  other.join();
  EXPECT_EQ(a.load(), 1000);
  EXPECT_EQ(b.load(), 1000);
}
