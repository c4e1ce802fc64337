// PatchMatch hole filling: the plain-data interface of the AVX2 and AVX-512 weighted-median
// kernels (median_avx2.cpp, median_avx512.cpp), under cost_kernel.h's rules: this header includes
// nothing, and each kernel runs only where the SimdPath it is given allows it (built with the
// matching cost kernel's flags).
#pragma once

namespace lidar_stereo_fusion {
namespace patchmatch {

/// Candidates of the weighted median whose cumulative weights are summed side by side: one lane
/// each, each lane summed in window order, so 8 AVX2 lanes and the scalar loop give one result.
constexpr int kMedianLanes = 8;

/// The colour-weighted median of d[i], i < n, as post_processing.cpp's weightedMedian: the
/// smallest d[i] whose cumulative weight (the sum of w[j] over d[j] <= d[i], in window order)
/// reaches `half`. d and w hold `padded` entries, a multiple of kMedianLanes, the padding with
/// the largest float and weight 0. Call only when the CPU has AVX2.
float weightedMedianAvx2(const float* d, const float* w, int n, int padded, float half);

/// weightedMedianAvx2 with AVX-512, 16 candidates per register: the same float. Call only when
/// the CPU has AVX-512 (simd.h).
float weightedMedianAvx512(const float* d, const float* w, int n, int padded, float half);

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
