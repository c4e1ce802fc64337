// PatchMatch: the matching cost C(p, xi) (cost.h) with AVX-512, 16 window samples at a time.
// Compiled with -mavx512f -mavx512bw -mavx512vl -mavx512dq -mfma -ffp-contract=off
// (CMakeLists.txt) and run only where the CPU and the operating system support them (simd.h).
// Includes nothing but intrinsics and the plain-data kernel interface (see cost_kernel.h).
//
// The AVX2 kernel's steps (cost_avx2.cpp), twice as wide: the float steps run on 16 lanes, each
// lane the same operations in the same order as there, and the two halves of the 16 terms are
// added to the same 8 lane sums one after the other, as the AVX2 kernel adds two blocks; so C is
// bit-identical to both other paths. The integer steps take four samples per operation instead
// of two: the 128-bit quarter q of a register holds sample 4 g + q of group g, so that the own
// texels of a group are one load.
#include "lidar_stereo_fusion/core/patchmatch/cost_kernel.h"

#if defined(__AVX512F__) && defined(__AVX512BW__) && defined(__AVX512VL__) && defined(__AVX512DQ__)

#include <immintrin.h>

// GCC 12's AVX-512 intrinsics pass an undefined register as the unused merge source, which
// -W(maybe-)uninitialized reports at -O3 (GCC bug 105593, fixed in GCC 13).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"

namespace lidar_stereo_fusion {
namespace patchmatch {

const bool kAvx512KernelBuilt = true;

namespace {

constexpr int kWide = 2 * kSimdBlock;  // samples per step
constexpr int kGroup = 4;              // samples per integer operation
constexpr int kGroups = kWide / kGroup;

/// The plane's match of the 16 samples from s (the first `lanes`, 8 or 16; the others read as
/// 0): d, the mask of matches inside the image, the left nodes' offsets in the other view's
/// texels (written to `node`) and the fractions in fixed point (16-bit, saturated as the AVX2
/// kernel's pack), in the low 256 bits.
struct WideMatch {
  __m512 d;
  __mmask16 inside;
  __m512i fractions;
};

inline WideMatch matchWide(const KernelWindow& w, const KernelConstants& k, int s, __mmask16 lanes,
                           __m512 va, __m512 vb, __m512 vc, int* node) {
  const __m512 zero = _mm512_setzero_ps();
  const __m512 x = _mm512_maskz_loadu_ps(lanes, w.xs + s);
  const __m512 y = _mm512_maskz_loadu_ps(lanes, w.ys + s);
  WideMatch m;
  m.d = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(va, x), _mm512_mul_ps(vb, y)), vc);
  const __m512 xm_raw = _mm512_add_ps(x, _mm512_mul_ps(_mm512_set1_ps(k.sign), m.d));
  m.inside = _mm512_cmp_ps_mask(xm_raw, zero, _CMP_GE_OQ) &
             _mm512_cmp_ps_mask(xm_raw, _mm512_set1_ps(k.x_max), _CMP_LE_OQ);
  const __m512 xm = _mm512_min_ps(_mm512_max_ps(xm_raw, zero), _mm512_set1_ps(k.x_clamp));
  const __m512i i0 = _mm512_cvttps_epi32(xm);
  const __m512 f = _mm512_sub_ps(xm, _mm512_cvtepi32_ps(i0));
  const __m512i f32 = _mm512_cvtps_epi32(_mm512_mul_ps(f, _mm512_set1_ps(kFracOne)));
  m.fractions = _mm512_castsi256_si512(_mm512_cvtsepi32_epi16(f32));
  const __m512i row = _mm512_maskz_loadu_epi32(lanes, w.texel_row + s);
  _mm512_store_si512(node, _mm512_add_epi32(row, _mm512_slli_epi32(i0, 3)));
  // The nodes are read back from memory as scalars: left to itself the compiler extracts them
  // from the register, two uops each on the port the shuffles need.
  asm volatile("" : : "r"(node) : "memory");
  return m;
}

/// Group g's |own - m| per channel (m interpolated between the nodes), own - m (out: diff) and
/// the nodes' difference (out: slope).
inline __m512i groupDifference(const short* other, const int* node, const short* own, int g,
                               __m512i fractions, __m512i& slope, __m512i& diff) {
  const int* n = node + g * kGroup;
  const auto nodes = [&](int i) {
    return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(other + n[i]));
  };
  // [t0 t1 of sample 0 | of sample 1] and the same of samples 2, 3; then the t0 and the t1 of the
  // four, in 64-bit halves of texels.
  const __m512i a = _mm512_inserti64x4(_mm512_castsi256_si512(nodes(0)), nodes(1), 1);
  const __m512i b = _mm512_inserti64x4(_mm512_castsi256_si512(nodes(2)), nodes(3), 1);
  const __m512i t0 = _mm512_permutex2var_epi64(a, _mm512_setr_epi64(0, 1, 4, 5, 8, 9, 12, 13), b);
  const __m512i t1 = _mm512_permutex2var_epi64(a, _mm512_setr_epi64(2, 3, 6, 7, 10, 11, 14, 15), b);
  slope = _mm512_sub_epi16(t1, t0);
  // Sample 4 g + q's fraction over the 8 channels of quarter q.
  const short f0 = static_cast<short>(g * kGroup);
  const __m512i pick = _mm512_set_epi16(f0 + 3, f0 + 3, f0 + 3, f0 + 3, f0 + 3, f0 + 3, f0 + 3,
                                        f0 + 3, f0 + 2, f0 + 2, f0 + 2, f0 + 2, f0 + 2, f0 + 2,
                                        f0 + 2, f0 + 2, f0 + 1, f0 + 1, f0 + 1, f0 + 1, f0 + 1,
                                        f0 + 1, f0 + 1, f0 + 1, f0, f0, f0, f0, f0, f0, f0, f0);
  const __m512i m =
      _mm512_add_epi16(t0, _mm512_mulhrs_epi16(slope, _mm512_permutexvar_epi16(pick, fractions)));
  diff = _mm512_sub_epi16(_mm512_loadu_si512(own + g * kGroup * kTexelChannels), m);
  return _mm512_abs_epi16(diff);
}

/// The colour L1 (out: col) and gradient L1 (out: grad) of the 16 samples, as floats in texel
/// units, from each group's |differences| summed by channel pairs (madd with ones): (B + G,
/// R + 0, gx + gy, 0 + 0) per sample.
inline void channelSums(const __m512i* group_sums, __m512& col, __m512& grad) {
  __m512i x[kGroups];
  for (int g = 0; g < kGroups; ++g) {
    // Per sample: B + G + R in its first 32 bits, gx + gy in its third.
    x[g] = _mm512_add_epi32(group_sums[g], _mm512_srli_epi64(group_sums[g], 32));
  }
  const __m512i split =
      _mm512_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28, 2, 6, 10, 14, 18, 22, 26, 30);
  const __m512i low = _mm512_permutex2var_epi32(x[0], split, x[1]);   // col 0..7, grad 0..7
  const __m512i high = _mm512_permutex2var_epi32(x[2], split, x[3]);  // col 8..15, grad 8..15
  col = _mm512_cvtepi32_ps(_mm512_permutex2var_epi32(
      low, _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 16, 17, 18, 19, 20, 21, 22, 23), high));
  grad = _mm512_cvtepi32_ps(_mm512_permutex2var_epi32(
      low, _mm512_setr_epi32(8, 9, 10, 11, 12, 13, 14, 15, 24, 25, 26, 27, 28, 29, 30, 31), high));
}

/// alpha min(col, lambda_col) + beta min(grad, lambda_grad), or the outside cost where the match
/// left the image.
inline __m512 imageTerm(const KernelConstants& k, __m512 col, __m512 grad, __mmask16 inside) {
  const __m512 rho = _mm512_add_ps(
      _mm512_mul_ps(_mm512_set1_ps(k.alpha), _mm512_min_ps(col, _mm512_set1_ps(k.lambda_col))),
      _mm512_mul_ps(_mm512_set1_ps(k.beta), _mm512_min_ps(grad, _mm512_set1_ps(k.lambda_grad))));
  return _mm512_mask_blend_ps(inside, _mm512_set1_ps(k.outside_cost), rho);
}

/// min(|prior - d|, lambda_disp).
inline __m512 lidarTerm(__m512 prior, __m512 d, __m512 ldisp) {
  return _mm512_min_ps(_mm512_abs_ps(_mm512_sub_ps(prior, d)), ldisp);
}

/// ((l0 + l4) + (l2 + l6)) + ((l1 + l5) + (l3 + l7)) of the 8 lanes (cost_kernel.h's order), as
/// cost_avx2.cpp's (files built for different instructions share no inline code: cost_kernel.h).
inline float laneSum(__m256 v) {
  const __m128 s4 = _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  const __m128 s2 = _mm_add_ps(s4, _mm_movehl_ps(s4, s4));
  return _mm_cvtss_f32(_mm_add_ss(s2, _mm_shuffle_ps(s2, s2, 1)));
}

/// Adds the 16 terms to the 8 lane sums: the first 8, then (if there are 16) the others, as the
/// AVX2 kernel adds two blocks.
inline __m256 addTerms(__m256 acc, __m512 terms, bool wide) {
  acc = _mm256_add_ps(acc, _mm512_castps512_ps256(terms));
  return wide ? _mm256_add_ps(acc, _mm512_extractf32x8_ps(terms, 1)) : acc;
}

/// Groups of the step from s that hold a real sample.
inline int realGroups(int real_count, int s) {
  const int left = (real_count - s + kGroup - 1) / kGroup;
  return left < kGroups ? left : kGroups;
}

}  // namespace

float aggregateAvx512(const KernelWindow& w, const KernelConstants& k, float a, float b, float c,
                      float bound) {
  if (w.constant >= bound) return w.constant;
  const __m512 va = _mm512_set1_ps(a), vb = _mm512_set1_ps(b), vc = _mm512_set1_ps(c);
  const __m512 ldisp = _mm512_set1_ps(k.lambda_disp);
  const __m512i ones = _mm512_set1_epi16(1);
  alignas(64) int node[kWide];
  __m256 acc = _mm256_setzero_ps();  // lane j sums the samples j, j + 8, ... (the baseline's)
  for (int s = 0; s < w.count; s += kWide) {
    // count is a multiple of 8: 16 samples, or the last 8.
    const bool wide = w.count - s >= kWide;
    const __mmask16 lanes = wide ? 0xFFFF : 0x00FF;
    const WideMatch m = matchWide(w, k, s, lanes, va, vb, vc, node);
    const short* own = w.texels + s * kTexelChannels;
    __m512i sums[kGroups] = {};
    const int groups = realGroups(w.real_count, s);
    for (int g = 0; g < groups; ++g) {
      __m512i slope, diff;
      sums[g] = _mm512_madd_epi16(
          groupDifference(k.other_texels, node, own, g, m.fractions, slope, diff), ones);
    }
    __m512 col, grad;
    channelSums(sums, col, grad);
    const __m512 rho_img = imageTerm(k, col, grad, m.inside);
    const __m512 rho_lid = lidarTerm(_mm512_maskz_loadu_ps(lanes, w.priors + s), m.d, ldisp);
    // Padding samples have zero weights: their term is exactly 0 and leaves the lanes unchanged.
    const __m512 terms =
        _mm512_add_ps(_mm512_mul_ps(_mm512_maskz_loadu_ps(lanes, w.w_img + s), rho_img),
                      _mm512_mul_ps(_mm512_maskz_loadu_ps(lanes, w.w_lidar + s), rho_lid));
    acc = addTerms(acc, terms, wide);
    // The bound is checked after every second block of 8, as the other paths do.
    if (wide) {
      const float sum = w.constant + laneSum(acc);
      if (sum >= bound) return sum;
    }
  }
  return w.constant + laneSum(acc);
}

void aggregateSidesAvx512(const KernelWindow& w, const KernelConstants& k, float a, float b,
                          float c, float h, int shift_q, float& lower, float& upper) {
  const __m512 va = _mm512_set1_ps(a), vb = _mm512_set1_ps(b), vc = _mm512_set1_ps(c);
  const __m512 vh = _mm512_set1_ps(h), ldisp = _mm512_set1_ps(k.lambda_disp);
  const __m512i ones = _mm512_set1_epi16(1);
  const __m512i shift = _mm512_set1_epi16(static_cast<short>(shift_q));
  alignas(64) int node[kWide];
  __m256 acc_lower = _mm256_setzero_ps(), acc_upper = _mm256_setzero_ps();
  for (int s = 0; s < w.count; s += kWide) {
    const bool wide = w.count - s >= kWide;
    const __mmask16 lanes = wide ? 0xFFFF : 0x00FF;
    const WideMatch m = matchWide(w, k, s, lanes, va, vb, vc, node);
    const short* own = w.texels + s * kTexelChannels;
    // own - m at d -+ h: own - m +- the nodes' difference times the shift, on d's interval.
    __m512i sums_lower[kGroups] = {}, sums_upper[kGroups] = {};
    const int groups = realGroups(w.real_count, s);
    for (int g = 0; g < groups; ++g) {
      __m512i slope, diff;
      groupDifference(k.other_texels, node, own, g, m.fractions, slope, diff);
      const __m512i moved = _mm512_mulhrs_epi16(slope, shift);
      sums_lower[g] = _mm512_madd_epi16(_mm512_abs_epi16(_mm512_add_epi16(diff, moved)), ones);
      sums_upper[g] = _mm512_madd_epi16(_mm512_abs_epi16(_mm512_sub_epi16(diff, moved)), ones);
    }
    __m512 col_lower, grad_lower, col_upper, grad_upper;
    channelSums(sums_lower, col_lower, grad_lower);
    channelSums(sums_upper, col_upper, grad_upper);
    const __m512 rho_lower = imageTerm(k, col_lower, grad_lower, m.inside);
    const __m512 rho_upper = imageTerm(k, col_upper, grad_upper, m.inside);
    const __m512 prior = _mm512_maskz_loadu_ps(lanes, w.priors + s);
    const __m512 w_img = _mm512_maskz_loadu_ps(lanes, w.w_img + s);
    const __m512 w_lidar = _mm512_maskz_loadu_ps(lanes, w.w_lidar + s);
    const __m512 lid_lower = lidarTerm(prior, _mm512_sub_ps(m.d, vh), ldisp);
    const __m512 lid_upper = lidarTerm(prior, _mm512_add_ps(m.d, vh), ldisp);
    acc_lower = addTerms(
        acc_lower,
        _mm512_add_ps(_mm512_mul_ps(w_img, rho_lower), _mm512_mul_ps(w_lidar, lid_lower)), wide);
    acc_upper = addTerms(
        acc_upper,
        _mm512_add_ps(_mm512_mul_ps(w_img, rho_upper), _mm512_mul_ps(w_lidar, lid_upper)), wide);
  }
  lower = w.constant + laneSum(acc_lower);
  upper = w.constant + laneSum(acc_upper);
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion

#else  // no AVX-512 in this build (non-x86): never selected, see simd.cpp

namespace lidar_stereo_fusion {
namespace patchmatch {

const bool kAvx512KernelBuilt = false;

float aggregateAvx512(const KernelWindow& w, const KernelConstants&, float, float, float, float) {
  return w.constant;
}

void aggregateSidesAvx512(const KernelWindow& w, const KernelConstants&, float, float, float, float,
                          int, float& lower, float& upper) {
  lower = upper = w.constant;
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion

#endif
