// PatchMatch: what the CPU runs of the cost kernels (see simd.h). No state beyond the CPU's
// features, detected once.
#include "lidar_stereo_fusion/core/patchmatch/simd.h"

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
  return patchmatch::kAvx512KernelBuilt && cpuHasAvx2Fma() && __builtin_cpu_supports("avx512f") &&
         __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl") &&
         __builtin_cpu_supports("avx512dq");
#else
  return false;
#endif
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

SimdPath widestSimdPath() {
  if (cpuHasAvx512()) return SimdPath::kAvx512;
  return cpuHasAvx2Fma() ? SimdPath::kAvx2 : SimdPath::kBaseline;
}

SimdPath capSimdPath(SimdPath requested) {
  const SimdPath widest = widestSimdPath();
  return static_cast<int>(requested) < static_cast<int>(widest) ? requested : widest;
}

const char* simdPathName(SimdPath path) {
  switch (path) {
    case SimdPath::kAvx512:
      return "avx512";
    case SimdPath::kAvx2:
      return "avx2";
    case SimdPath::kBaseline:
      break;
  }
  return "baseline";
}

bool parseSimdPath(const std::string& name, SimdPath& path) {
  for (const SimdPath p : {SimdPath::kBaseline, SimdPath::kAvx2, SimdPath::kAvx512}) {
    if (name == simdPathName(p)) {
      path = p;
      return true;
    }
  }
  return false;
}

}  // namespace lidar_stereo_fusion
