// PatchMatch hole filling: the weighted median's cumulative weights with AVX-512, 16 candidates
// per register (median_kernel.h). Compiled with cost_avx512.cpp's flags (CMakeLists.txt); only
// compares and masked adds, each lane summed in window order: the baseline's floats exactly
// (a lane not below adds nothing, where the other paths add 0 to a sum that is never -0).
#include "lidar_stereo_fusion/core/patchmatch/median_kernel.h"

#if defined(__AVX512F__) && defined(__AVX512BW__) && defined(__AVX512VL__) && defined(__AVX512DQ__)

#include <immintrin.h>

// GCC 12's AVX-512 intrinsics pass an undefined register as the unused merge source, which
// -W(maybe-)uninitialized reports at -O3 (GCC bug 105593, fixed in GCC 13).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"

namespace lidar_stereo_fusion {
namespace patchmatch {

namespace {

constexpr int kWide = 16;  // candidates per register
/// Registers of candidates summed side by side: independent sums (see median_avx2.cpp).
constexpr int kGroups = 3;

}  // namespace

float weightedMedianAvx512(const float* d, const float* w, int n, int padded, float half) {
  const __m512 vhalf = _mm512_set1_ps(half), largest = _mm512_set1_ps(__FLT_MAX__);
  __m512 best = largest;
  for (int i0 = 0; i0 < padded; i0 += kGroups * kWide) {
    __m512 candidate[kGroups], cumulative[kGroups];
    for (int g = 0; g < kGroups; ++g) {
      // Candidates past the padding are the largest float: their sum is all, the minimum keeps.
      const int first = i0 + g * kWide;
      const int left = padded - first;
      const __mmask16 real = left >= kWide ? 0xFFFF : (left > 0 ? (1u << left) - 1u : 0u);
      candidate[g] = _mm512_mask_loadu_ps(largest, real, d + (left > 0 ? first : 0));
      cumulative[g] = _mm512_setzero_ps();
    }
    for (int j = 0; j < n; ++j) {
      const __m512 dj = _mm512_set1_ps(d[j]), wj = _mm512_set1_ps(w[j]);
      for (int g = 0; g < kGroups; ++g) {
        const __mmask16 below = _mm512_cmp_ps_mask(dj, candidate[g], _CMP_LE_OQ);
        cumulative[g] = _mm512_mask_add_ps(cumulative[g], below, cumulative[g], wj);
      }
    }
    // Candidates that qualify keep their value, the others the largest float.
    for (int g = 0; g < kGroups; ++g) {
      const __mmask16 qualifies = _mm512_cmp_ps_mask(cumulative[g], vhalf, _CMP_GE_OQ);
      best = _mm512_min_ps(best, _mm512_mask_blend_ps(qualifies, largest, candidate[g]));
    }
  }
  return _mm512_reduce_min_ps(best);
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion

#else  // no AVX-512 in this build: never selected (simdPathSupported(kAvx512) is false)

namespace lidar_stereo_fusion {
namespace patchmatch {

float weightedMedianAvx512(const float* d, const float*, int, int, float) { return d[0]; }

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion

#endif
