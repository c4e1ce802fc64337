// PatchMatch: which implementation of the matching-cost kernel runs (runtime SIMD dispatch).
//
// The binary is built for baseline x86-64; the cost kernel also exists as an AVX2 + FMA version
// (cost_avx2.cpp, built with -mavx2 -mfma) chosen at run time when the CPU has both. The
// environment variable LSF_SIMD=baseline (read once, at the first use) forces the baseline path;
// setSimdPath() switches paths in-process (tests, benchmarks).
#pragma once

namespace lidar_stereo_fusion {

enum class SimdPath { kBaseline, kAvx2 };

/// Whether the AVX2 kernel was compiled in and this CPU has AVX2 and FMA.
bool cpuHasAvx2Fma();

/// The path the matching cost uses: kAvx2 when cpuHasAvx2Fma() unless LSF_SIMD=baseline or
/// setSimdPath() chose otherwise.
SimdPath activeSimdPath();

/// Name of the active path: "avx2" or "baseline" (for tool headers and logs).
const char* simdLevel();

/// Selects the path for PatchMatch computations started afterwards (not while one runs).
/// Throws std::invalid_argument for kAvx2 when !cpuHasAvx2Fma().
void setSimdPath(SimdPath path);

}  // namespace lidar_stereo_fusion
