// Helpers of the SIMD tests (test_cost_simd.cpp, test_cost_simd_kernels.cpp): the wide paths this
// CPU runs and a skip on CPUs without AVX2.
#pragma once

#include <vector>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/patchmatch/simd.h"

#define SKIP_WITHOUT_AVX2()                                                               \
  if (!lidar_stereo_fusion::cpuHasAvx2Fma()) {                                            \
    GTEST_SKIP() << "this CPU (or build) has no AVX2 + FMA: only the baseline path runs"; \
  }

namespace lidar_stereo_fusion {
namespace test {

/// The SIMD paths this CPU runs besides the baseline.
inline std::vector<SimdPath> widePaths() {
  std::vector<SimdPath> paths;
  for (const SimdPath path : {SimdPath::kAvx2, SimdPath::kAvx512}) {
    if (simdPathSupported(path)) paths.push_back(path);
  }
  return paths;
}

}  // namespace test
}  // namespace lidar_stereo_fusion
