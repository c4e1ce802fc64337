// PatchMatch: which implementation of the matching-cost kernel runs (runtime SIMD dispatch).
//
// The binary is built for baseline x86-64; the cost kernel also exists as an AVX2 + FMA version
// (cost_avx2.cpp, built with -mavx2 -mfma) and AVX-512 versions of its aggregation and of the
// fill's weighted median (*_avx512.cpp, F + BW + VL + DQ). All paths give bit-identical results.
// The path is a value each computation is given (PatchMatchParams::simd_path, by default the
// widest this CPU runs); the core keeps no process-wide choice and reads no environment. Tools
// and the nodelet may take it from the environment variable LSF_SIMD (io/simd_env.h).
#pragma once

#include <string>

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

/// The widest path this CPU and build run (PatchMatchParams' default).
SimdPath widestSimdPath();

/// `requested`, narrowed to the widest path this CPU and build run.
SimdPath capSimdPath(SimdPath requested);

/// Name of a path: "avx512", "avx2" or "baseline" (for tool headers and logs).
const char* simdPathName(SimdPath path);

/// Parses a name of simdPathName(); false (and `path` untouched) for anything else.
bool parseSimdPath(const std::string& name, SimdPath& path);

}  // namespace lidar_stereo_fusion
