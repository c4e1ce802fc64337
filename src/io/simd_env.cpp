// The SIMD path from LSF_SIMD (simd_env.h).
#include "lidar_stereo_fusion/io/simd_env.h"

#include <cstdlib>
#include <iostream>

#include "lidar_stereo_fusion/core/pipeline.h"

namespace lidar_stereo_fusion {

SimdPath simdPathFromEnvironment(std::string* warning) {
  const char* env = std::getenv("LSF_SIMD");
  if (env == nullptr || *env == '\0') return widestSimdPath();
  SimdPath requested;
  if (parseSimdPath(env, requested)) return capSimdPath(requested);
  if (warning != nullptr) {
    *warning = std::string("LSF_SIMD=") + env +
               " is not baseline, avx2 or avx512; using the widest path this CPU runs (" +
               simdPathName(widestSimdPath()) + ")";
  }
  return widestSimdPath();
}

SimdPath applySimdEnvironment(FusionParams& params) {
  std::string warning;
  params.patchmatch.simd_path = simdPathFromEnvironment(&warning);
  if (!warning.empty()) std::cerr << "lidar_stereo_fusion: " << warning << "\n";
  return params.patchmatch.simd_path;
}

}  // namespace lidar_stereo_fusion
