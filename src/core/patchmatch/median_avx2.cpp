// PatchMatch hole filling: the weighted median's cumulative weights with AVX2, 8 candidates at a
// time (median_kernel.h). Compiled with cost_avx2.cpp's flags (CMakeLists.txt); only compares,
// ands and adds, each lane summed in window order: the baseline's floats exactly.
#include "lidar_stereo_fusion/core/patchmatch/median_kernel.h"

#if defined(__AVX2__) && defined(__FMA__)

#include <immintrin.h>

namespace lidar_stereo_fusion {
namespace patchmatch {

namespace {

/// Groups of kMedianLanes candidates summed side by side: independent sums, so that the adds of
/// one group do not wait for each other's (a single group's sum is one chain of dependent adds).
constexpr int kGroups = 4;

}  // namespace

float weightedMedianAvx2(const float* d, const float* w, int n, int padded, float half) {
  const __m256 vhalf = _mm256_set1_ps(half), largest = _mm256_set1_ps(__FLT_MAX__);
  __m256 best = largest;
  for (int i0 = 0; i0 < padded; i0 += kGroups * kMedianLanes) {
    const int groups =
        (padded - i0) / kMedianLanes < kGroups ? (padded - i0) / kMedianLanes : kGroups;
    __m256 candidate[kGroups], cumulative[kGroups];
    for (int g = 0; g < kGroups; ++g) {
      // Groups past the padding repeat the last one: the same sums, the same minimum.
      candidate[g] = _mm256_loadu_ps(d + i0 + (g < groups ? g : groups - 1) * kMedianLanes);
      cumulative[g] = _mm256_setzero_ps();
    }
    for (int j = 0; j < n; ++j) {
      const __m256 dj = _mm256_broadcast_ss(d + j), wj = _mm256_broadcast_ss(w + j);
      for (int g = 0; g < kGroups; ++g) {
        const __m256 below = _mm256_cmp_ps(dj, candidate[g], _CMP_LE_OQ);
        cumulative[g] = _mm256_add_ps(cumulative[g], _mm256_and_ps(below, wj));
      }
    }
    // Candidates that qualify keep their value, the others the largest float.
    for (int g = 0; g < kGroups; ++g) {
      const __m256 qualifies = _mm256_cmp_ps(cumulative[g], vhalf, _CMP_GE_OQ);
      best = _mm256_min_ps(best, _mm256_blendv_ps(largest, candidate[g], qualifies));
    }
  }
  const __m128 m4 = _mm_min_ps(_mm256_castps256_ps128(best), _mm256_extractf128_ps(best, 1));
  const __m128 m2 = _mm_min_ps(m4, _mm_movehl_ps(m4, m4));
  return _mm_cvtss_f32(_mm_min_ss(m2, _mm_shuffle_ps(m2, m2, 1)));
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion

#else  // no AVX2 + FMA in this build: never selected (simdPathSupported(kAvx2) is false)

namespace lidar_stereo_fusion {
namespace patchmatch {

float weightedMedianAvx2(const float* d, const float*, int, int, float) { return d[0]; }

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion

#endif
