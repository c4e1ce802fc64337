// PatchMatch: which implementation of the matching-cost kernel runs (runtime SIMD dispatch).
//
// The binary is built for baseline x86-64; the cost kernel also exists as an AVX2 + FMA version
// (cost_avx2.cpp, built with -mavx2 -mfma) and AVX-512 versions of its aggregation and of the
// fill's weighted median (*_avx512.cpp, F + BW + VL + DQ), chosen at run time: the widest the CPU
// (and the operating system) supports. All paths give bit-identical results. The environment
// variable LSF_SIMD (read once, at the first use) caps it: `baseline` or `avx2`; setSimdPath()
// switches paths in-process (tests, benchmarks).
#pragma once

namespace lidar_stereo_fusion {

/// Ordered: each path uses the instructions of the ones before it.
enum class SimdPath { kBaseline, kAvx2, kAvx512 };

/// Whether the AVX2 kernel was compiled in and this CPU has AVX2 and FMA.
bool cpuHasAvx2Fma();

/// Whether the AVX-512 kernel was compiled in, this CPU has AVX-512 F, BW, VL and DQ (and AVX2 +
/// FMA) and the operating system keeps the 512-bit registers.
bool cpuHasAvx512();

/// Whether this CPU and build can run `path`.
bool simdPathSupported(SimdPath path);

/// The path the matching cost uses: the widest supported one, unless LSF_SIMD or setSimdPath()
/// chose otherwise.
SimdPath activeSimdPath();

/// Name of the active path: "avx512", "avx2" or "baseline" (for tool headers and logs).
const char* simdLevel();

/// Selects the path for PatchMatch computations started afterwards (not while one runs).
/// Throws std::invalid_argument for a path !simdPathSupported().
void setSimdPath(SimdPath path);

}  // namespace lidar_stereo_fusion
