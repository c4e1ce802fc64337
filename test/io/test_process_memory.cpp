// keepFreedMemory: freed memory stays with the process, so a frame reuses the pages of the frame
// before instead of faulting new ones in (io/process_memory.h).
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <string>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "lidar_stereo_fusion/io/process_memory.h"

namespace lsf = lidar_stereo_fusion;

#if defined(__GLIBC__)
// Each in a fresh process (the death tests' "threadsafe" style runs the binary again for the test
// alone): no other test runs with the setting, and no other test's blocks moved glibc's thresholds.
TEST(ProcessMemory, AFrameSizedBlockComesFromTheHeapAndStaysWhenFreed) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  constexpr size_t kBlock = 16u << 20;  // 16 MB: above glibc's default thresholds
  EXPECT_EXIT(
      {
        std::string problem;
        if (!lsf::keepFreedMemory(&problem)) std::_Exit(1);
        const struct mallinfo2 before = mallinfo2();
        void* block = std::malloc(kBlock);
        if (block == nullptr) std::_Exit(2);
        std::memset(block, 1, kBlock);
        const struct mallinfo2 held = mallinfo2();
        std::free(block);
        const struct mallinfo2 after = mallinfo2();
        if (held.hblks != before.hblks) std::_Exit(3);  // not a mapping of its own
        if (after.keepcost < kBlock) std::_Exit(4);     // the freed pages stay at the heap's top
        std::_Exit(0);
      },
      ::testing::ExitedWithCode(0), "");
}

TEST(ProcessMemory, WithoutItABlockThatSizeIsAMappingOfItsOwn) {
  // The default the setting changes (so that the test above could fail): a fresh process maps
  // a block above the mmap threshold by itself and unmaps it when freed.
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  constexpr size_t kBlock = 16u << 20;
  EXPECT_EXIT(
      {
        const struct mallinfo2 before = mallinfo2();
        void* block = std::malloc(kBlock);
        if (block == nullptr) std::_Exit(2);
        const struct mallinfo2 held = mallinfo2();
        std::free(block);
        std::_Exit(held.hblks == before.hblks + 1 ? 0 : 3);
      },
      ::testing::ExitedWithCode(0), "");
}
#else
TEST(ProcessMemory, OtherCLibrariesSayWhy) {
  std::string problem;
  EXPECT_FALSE(lsf::keepFreedMemory(&problem));
  EXPECT_NE(problem.find("not glibc"), std::string::npos);
}
#endif
