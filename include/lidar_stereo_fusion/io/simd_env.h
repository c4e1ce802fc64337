// The SIMD path from the environment, for the tools and the nodelet (the core reads none).
// ROS-free.
#pragma once

#include <string>

#include "lidar_stereo_fusion/core/patchmatch/simd.h"

namespace lidar_stereo_fusion {

struct FusionParams;

/// The path a tool runs: the widest this CPU runs, capped by the environment variable LSF_SIMD
/// (`baseline`, `avx2` or `avx512`; unset or empty: no cap). Another value is reported in
/// `warning` (if given: "LSF_SIMD=... is not baseline, avx2 or avx512; ...") and caps nothing.
SimdPath simdPathFromEnvironment(std::string* warning = nullptr);

/// Sets params.patchmatch.simd_path to simdPathFromEnvironment(), printing its warning, if any,
/// on stderr. Returns the path.
SimdPath applySimdEnvironment(FusionParams& params);

}  // namespace lidar_stereo_fusion
