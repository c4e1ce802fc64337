// PatchMatch: runtime selection of the cost kernel (see simd.h).
#include "lidar_stereo_fusion/core/patchmatch/simd.h"

#include <atomic>
#include <cstdio>
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

bool detectAvx512() {
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
  // libgcc reports AVX-512 features only where XGETBV says the OS saves the 512-bit state.
  __builtin_cpu_init();
  return patchmatch::kAvx512KernelBuilt && cpuHasAvx2Fma() &&
         __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
         __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq");
#else
  return false;
#endif
}

SimdPath widestPath() {
  if (cpuHasAvx512()) return SimdPath::kAvx512;
  return cpuHasAvx2Fma() ? SimdPath::kAvx2 : SimdPath::kBaseline;
}

/// The path at start-up: the widest the CPU runs, capped by LSF_SIMD (baseline, avx2).
SimdPath initialPath() {
  const SimdPath widest = widestPath();
  const char* env = std::getenv("LSF_SIMD");
  if (env == nullptr || *env == '\0') return widest;
  if (std::strcmp(env, "baseline") == 0) return SimdPath::kBaseline;
  if (std::strcmp(env, "avx2") == 0) {
    return widest == SimdPath::kBaseline ? SimdPath::kBaseline : SimdPath::kAvx2;
  }
  if (std::strcmp(env, "avx512") != 0) {
    std::fprintf(stderr, "lidar_stereo_fusion: LSF_SIMD=%s is not baseline, avx2 or avx512; "
                 "using the widest path this CPU runs\n", env);
  }
  return widest;
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

bool cpuHasAvx512() {
  static const bool has = detectAvx512();
  return has;
}

bool simdPathSupported(SimdPath path) {
  switch (path) {
    case SimdPath::kBaseline:
      return true;
    case SimdPath::kAvx2:
      return cpuHasAvx2Fma();
    case SimdPath::kAvx512:
      return cpuHasAvx512();
  }
  return false;
}

SimdPath activeSimdPath() { return static_cast<SimdPath>(pathStore().load()); }

const char* simdLevel() {
  switch (activeSimdPath()) {
    case SimdPath::kAvx512:
      return "avx512";
    case SimdPath::kAvx2:
      return "avx2";
    case SimdPath::kBaseline:
      break;
  }
  return "baseline";
}

void setSimdPath(SimdPath path) {
  if (!simdPathSupported(path)) {
    throw std::invalid_argument(path == SimdPath::kAvx512
                                    ? "setSimdPath: this CPU (or build) has no AVX-512"
                                    : "setSimdPath: this CPU (or build) has no AVX2 + FMA");
  }
  pathStore().store(static_cast<int>(path));
}

}  // namespace lidar_stereo_fusion
