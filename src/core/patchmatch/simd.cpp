// PatchMatch: runtime selection of the cost kernel (see simd.h).
#include "lidar_stereo_fusion/core/patchmatch/simd.h"

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "lidar_stereo_fusion/core/patchmatch/cost_kernel.h"

namespace lidar_stereo_fusion {

namespace {

bool detectAvx2Fma() {
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
  __builtin_cpu_init();
  return patchmatch::kAvx2KernelBuilt && __builtin_cpu_supports("avx2") &&
         __builtin_cpu_supports("fma");
#else
  return false;
#endif
}

/// The path at start-up: the best the CPU runs, unless LSF_SIMD=baseline.
SimdPath initialPath() {
  const char* env = std::getenv("LSF_SIMD");
  if (env != nullptr && std::strcmp(env, "baseline") == 0) return SimdPath::kBaseline;
  return cpuHasAvx2Fma() ? SimdPath::kAvx2 : SimdPath::kBaseline;
}

std::atomic<int>& pathStore() {
  static std::atomic<int> path(static_cast<int>(initialPath()));
  return path;
}

}  // namespace

bool cpuHasAvx2Fma() {
  static const bool has = detectAvx2Fma();
  return has;
}

SimdPath activeSimdPath() { return static_cast<SimdPath>(pathStore().load()); }

const char* simdLevel() { return activeSimdPath() == SimdPath::kAvx2 ? "avx2" : "baseline"; }

void setSimdPath(SimdPath path) {
  if (path == SimdPath::kAvx2 && !cpuHasAvx2Fma()) {
    throw std::invalid_argument("setSimdPath: this CPU (or build) has no AVX2 + FMA");
  }
  pathStore().store(static_cast<int>(path));
}

}  // namespace lidar_stereo_fusion
