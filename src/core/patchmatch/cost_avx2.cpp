// PatchMatch: the matching cost C(p, xi) (cost.h) and its window with AVX2, 8 window samples at
// a time. Compiled with -mavx2 -mfma -ffp-contract=off (CMakeLists.txt) and run only where the CPU
// has both (simd.h); no FMA instruction is used, so that results stay the baseline's.
// Includes nothing but intrinsics and the plain-data kernel interface (see cost_kernel.h).
//
// Per block of 8 samples: the disparity d, the match x_q and its interpolation weight f are
// computed as vectors; then, per sample, the two texels around x_q (B, G, R, 0, gx, gy, 0, 0) are
// loaded as two 8-float vectors, interpolated and compared with the sample's own
// texel; a tree of horizontal adds turns the 8 per-sample difference vectors into the colour L1
// and gradient L1 of the 8 samples; the 8 terms are added to 8 lane sums. Every float operation
// is the baseline's, in its order (no FMA contraction, the lanes and their reduction as in
// cost_kernel.h), so both paths give bit-identical costs and PatchMatch results do not depend on
// the CPU.
#include "lidar_stereo_fusion/core/patchmatch/cost_kernel.h"

#if defined(__AVX2__) && defined(__FMA__)

#include <immintrin.h>

namespace lidar_stereo_fusion {
namespace patchmatch {

const bool kAvx2KernelBuilt = true;

namespace {

constexpr int kMaxOffsets = 101;  // window_radius <= 50 (PatchMatchParams::validate)

/// |own - interpolated| per texel channel of one sample; `t` the left node's texel, f in [0, 1).
inline __m256 texelDifference(const float* t, const float* f, const float* own, __m256 abs_mask) {
  const __m256 t0 = _mm256_load_ps(t);  // texels are 32-byte aligned (cost_kernel.h)
  const __m256 t1 = _mm256_load_ps(t + kTexelFloats);
  const __m256 m = _mm256_add_ps(t0, _mm256_mul_ps(_mm256_broadcast_ss(f), _mm256_sub_ps(t1, t0)));
  return _mm256_and_ps(abs_mask, _mm256_sub_ps(_mm256_loadu_ps(own), m));
}

/// Colour L1 (out: col) and gradient L1 (out: grad) of 8 samples from their per-channel
/// differences D_k = (dB, dG, dR, 0, dgx, dgy, 0, 0): (dB + dG) + dR and dgx + dgy, as scalar.
inline void channelSums(const __m256* dk, __m256& col, __m256& grad) {
  const __m256 h01 = _mm256_hadd_ps(dk[0], dk[1]);
  const __m256 h23 = _mm256_hadd_ps(dk[2], dk[3]);
  const __m256 h45 = _mm256_hadd_ps(dk[4], dk[5]);
  const __m256 h67 = _mm256_hadd_ps(dk[6], dk[7]);
  const __m256 s0123 = _mm256_hadd_ps(h01, h23);  // colour of 0..3 | gradient of 0..3
  const __m256 s4567 = _mm256_hadd_ps(h45, h67);
  col = _mm256_permute2f128_ps(s0123, s4567, 0x20);
  grad = _mm256_permute2f128_ps(s0123, s4567, 0x31);
}

/// ((l0 + l4) + (l2 + l6)) + ((l1 + l5) + (l3 + l7)) of the 8 lanes (cost_kernel.h's order).
inline float laneSum(__m256 v) {
  const __m128 s4 = _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  const __m128 s2 = _mm_add_ps(s4, _mm_movehl_ps(s4, s4));
  return _mm_cvtss_f32(_mm_add_ss(s2, _mm_shuffle_ps(s2, s2, 1)));
}

/// Pass 1 of buildWindowAvx2: positions, texels and priors of the samples inside the image, then
/// the padding; the trust is parked in w_lidar. Returns the number of real samples. Per row, the
/// positions are written 8 at a time (the arrays have kSimdBlock entries of room; what a row
/// writes beyond its samples is overwritten by the next row or the padding).
int gatherSamples(const KernelSelf& s, int px, int py, const KernelWindowOut& out, int padded_max) {
  // The offsets increase, so the columns inside the image are one range [j0, j1).
  int j0 = 0, j1 = s.offset_count;
  while (j0 < j1 && px + s.offsets[j0] < 0) ++j0;
  while (j1 > j0 && px + s.offsets[j1 - 1] >= s.width) --j1;
  const int m = j1 - j0;
  // Locals, not s's members: the stores below could alias them as far as the compiler knows.
  const int* const cols = s.offsets + j0;
  const float* const texels = s.texels;
  const float* const prior = s.prior;
  const float* const trust = s.trust;
  alignas(32) float xcol[kMaxOffsets + kSimdBlock];
  for (int j = 0; j < m + kSimdBlock; ++j) {
    xcol[j] = j < m ? static_cast<float>(px + s.offsets[j0 + j]) : 0.f;
  }
  int k = 0;
  for (int i = 0; i < s.offset_count; ++i) {
    const int y = py + s.offsets[i];
    if (y < 0 || y >= s.height) continue;
    const __m256 fy = _mm256_set1_ps(static_cast<float>(y));
    const __m256i row = _mm256_set1_epi32(y * s.other_texel_stride);
    for (int q = 0; q < m; q += kSimdBlock) {
      _mm256_storeu_ps(out.xs + k + q, _mm256_load_ps(xcol + q));
      _mm256_storeu_ps(out.ys + k + q, fy);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out.texel_row + k + q), row);
    }
    const float* texel_row = texels + (static_cast<long>(y) * s.width + px) * kTexelFloats;
    float* own = out.texels + k * kTexelFloats;
    for (int j = 0; j < m; ++j) {
      _mm256_store_ps(own + j * kTexelFloats, _mm256_load_ps(texel_row + cols[j] * kTexelFloats));
    }
    float* priors = out.priors + k;
    float* trusts = out.w_lidar + k;
    if (prior != nullptr) {
      const float* prior_row = prior + static_cast<long>(y) * s.prior_step + px;
      const float* trust_row = trust + static_cast<long>(y) * s.trust_step + px;
      for (int j = 0; j < m; ++j) {
        priors[j] = prior_row[cols[j]];
        trusts[j] = trust_row[cols[j]];
      }
    } else {
      for (int j = 0; j < m; ++j) priors[j] = trusts[j] = 0.f;
    }
    k += m;
  }
  for (int j = k; j < padded_max; ++j) {  // zero-weight padding at the first sample's position
    out.xs[j] = out.xs[0];
    out.ys[j] = out.ys[0];
    out.texel_row[j] = out.texel_row[0];
    _mm256_store_ps(out.texels + j * kTexelFloats, _mm256_setzero_ps());
    out.priors[j] = 0.f;
    out.w_lidar[j] = 0.f;
  }
  return k;
}

}  // namespace

int buildWindowAvx2(const KernelSelf& s, int px, int py, const KernelWindowOut& out, int& padded,
                    float& constant) {
  const int n = s.offset_count * s.offset_count;
  const int count = gatherSamples(s, px, py, out, (n + kSimdBlock - 1) / kSimdBlock * kSimdBlock);
  padded = (count + kSimdBlock - 1) / kSimdBlock * kSimdBlock;
  constant = 0.f;
  const __m256 center =
      _mm256_loadu_ps(s.texels + (static_cast<long>(py) * s.width + px) * kTexelFloats);
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  const __m256 lut_scale = _mm256_set1_ps(s.lut_scale);
  const __m256 lut_last = _mm256_set1_ps(static_cast<float>(s.lut_size - 1));
  const __m256 gamma = _mm256_set1_ps(s.gamma), one = _mm256_set1_ps(1.f);
  const __m256 img_norm = _mm256_set1_ps(s.img_norm), ldisp = _mm256_set1_ps(s.lambda_disp);
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const bool paper_constant = !s.weighted && s.prior != nullptr;
  alignas(32) float empty_cost[kSimdBlock];
  for (int b = 0; b < padded; b += kSimdBlock) {
    __m256 dk[kSimdBlock];
    for (int j = 0; j < kSimdBlock; ++j) {
      dk[j] = _mm256_and_ps(
          abs_mask, _mm256_sub_ps(_mm256_loadu_ps(out.texels + (b + j) * kTexelFloats), center));
    }
    __m256 l1, unused;
    channelSums(dk, l1, unused);
    // w = LUT[min(lut_size - 1, int(l1 * lut_scale))] (l1 >= 0), 0 on the padding.
    const __m256i index =
        _mm256_cvttps_epi32(_mm256_min_ps(_mm256_mul_ps(l1, lut_scale), lut_last));
    const __m256 valid =
        _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(count - b), lane));
    // Eight scalar loads, not a gather instruction: with the microcode mitigation of gather data
    // sampling on current Intel CPUs a gather costs a fifth of the whole window build.
    alignas(32) int lut_index[kSimdBlock];
    _mm256_store_si256(reinterpret_cast<__m256i*>(lut_index), index);
    const float* lut = s.weight_lut;
    const __m256 looked_up =
        _mm256_setr_ps(lut[lut_index[0]], lut[lut_index[1]], lut[lut_index[2]], lut[lut_index[3]],
                       lut[lut_index[4]], lut[lut_index[5]], lut[lut_index[6]], lut[lut_index[7]]);
    const __m256 w = _mm256_and_ps(valid, looked_up);
    const __m256 trust = _mm256_loadu_ps(out.w_lidar + b);
    if (s.weighted) {  // phi = (1 - kappa) / (alpha + beta) rho_img + kappa rho_lid
      const __m256 kappa = _mm256_mul_ps(gamma, trust);
      _mm256_storeu_ps(out.w_img + b,
                       _mm256_mul_ps(_mm256_mul_ps(w, _mm256_sub_ps(one, kappa)), img_norm));
      _mm256_storeu_ps(out.w_lidar + b, _mm256_mul_ps(w, kappa));
      continue;
    }
    // The paper: phi = rho_img + gamma rho_lid, or + gamma lambda_disp without a prior value.
    const __m256 has_value = _mm256_cmp_ps(trust, _mm256_setzero_ps(), _CMP_GT_OQ);
    const __m256 w_gamma = _mm256_mul_ps(w, gamma);
    _mm256_storeu_ps(out.w_img + b, w);
    _mm256_storeu_ps(out.w_lidar + b, _mm256_and_ps(has_value, w_gamma));
    if (!paper_constant) continue;
    _mm256_store_ps(empty_cost, _mm256_andnot_ps(has_value, _mm256_mul_ps(w_gamma, ldisp)));
    for (int j = 0; j < kSimdBlock; ++j) constant += empty_cost[j];  // the scalar code's order
  }
  return count;
}

float aggregateAvx2(const KernelWindow& w, const KernelConstants& k, float a, float b, float c,
                    float bound) {
  if (w.constant >= bound) return w.constant;
  const __m256 va = _mm256_set1_ps(a), vb = _mm256_set1_ps(b), vc = _mm256_set1_ps(c);
  const __m256 sign = _mm256_set1_ps(k.sign), zero = _mm256_setzero_ps();
  const __m256 x_max = _mm256_set1_ps(k.x_max), x_clamp = _mm256_set1_ps(k.x_clamp);
  const __m256 alpha = _mm256_set1_ps(k.alpha), beta = _mm256_set1_ps(k.beta);
  const __m256 lcol = _mm256_set1_ps(k.lambda_col), lgrad = _mm256_set1_ps(k.lambda_grad);
  const __m256 ldisp = _mm256_set1_ps(k.lambda_disp), outside = _mm256_set1_ps(k.outside_cost);
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  alignas(32) int offset[kSimdBlock];
  alignas(32) float frac[kSimdBlock];
  __m256 acc = zero;  // lane j sums the samples j, j + 8, j + 16, ... (the baseline's lanes)
  for (int s = 0; s < w.count; s += kSimdBlock) {
    // Each operation as the baseline code does it (no FMA; -ffp-contract=off for this file).
    const __m256 x = _mm256_loadu_ps(w.xs + s);
    const __m256 y = _mm256_loadu_ps(w.ys + s);
    const __m256 d = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(va, x), _mm256_mul_ps(vb, y)), vc);
    const __m256 xm_raw = _mm256_add_ps(x, _mm256_mul_ps(sign, d));
    const __m256 inside = _mm256_and_ps(_mm256_cmp_ps(xm_raw, zero, _CMP_GE_OQ),
                                        _mm256_cmp_ps(xm_raw, x_max, _CMP_LE_OQ));
    const __m256 xm = _mm256_min_ps(_mm256_max_ps(xm_raw, zero), x_clamp);
    const __m256i i0 = _mm256_cvttps_epi32(xm);
    _mm256_store_ps(frac, _mm256_sub_ps(xm, _mm256_cvtepi32_ps(i0)));
    const __m256i row = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(w.texel_row + s));
    _mm256_store_si256(reinterpret_cast<__m256i*>(offset),
                       _mm256_add_epi32(row, _mm256_slli_epi32(i0, 3)));
    __m256 dk[kSimdBlock];
    const float* own = w.texels + s * kTexelFloats;
    for (int j = 0; j < kSimdBlock; ++j) {
      dk[j] =
          texelDifference(k.other_texels + offset[j], frac + j, own + j * kTexelFloats, abs_mask);
    }
    __m256 col, grad;
    channelSums(dk, col, grad);
    __m256 rho_img = _mm256_add_ps(_mm256_mul_ps(alpha, _mm256_min_ps(col, lcol)),
                                   _mm256_mul_ps(beta, _mm256_min_ps(grad, lgrad)));
    rho_img = _mm256_blendv_ps(outside, rho_img, inside);
    const __m256 lid = _mm256_and_ps(abs_mask, _mm256_sub_ps(_mm256_loadu_ps(w.priors + s), d));
    const __m256 rho_lid = _mm256_min_ps(lid, ldisp);
    // Padding samples have zero weights: their term is exactly 0 and leaves the lanes unchanged.
    acc = _mm256_add_ps(acc, _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(w.w_img + s), rho_img),
                                           _mm256_mul_ps(_mm256_loadu_ps(w.w_lidar + s), rho_lid)));
    // The bound is checked after every block, as the baseline does: the same exit, the same float.
    const float sum = w.constant + laneSum(acc);
    if (sum >= bound) return sum;
  }
  return w.constant + laneSum(acc);
}

void aggregateSidesAvx2(const KernelWindow& w, const KernelConstants& k, float a, float b,
                        float c, float h, float& lower, float& upper) {
  const __m256 va = _mm256_set1_ps(a), vb = _mm256_set1_ps(b), vc = _mm256_set1_ps(c);
  const __m256 sign = _mm256_set1_ps(k.sign), zero = _mm256_setzero_ps();
  const __m256 vh = _mm256_set1_ps(h), shift = _mm256_set1_ps(k.sign * h);
  const __m256 x_max = _mm256_set1_ps(k.x_max), x_clamp = _mm256_set1_ps(k.x_clamp);
  const __m256 alpha = _mm256_set1_ps(k.alpha), beta = _mm256_set1_ps(k.beta);
  const __m256 lcol = _mm256_set1_ps(k.lambda_col), lgrad = _mm256_set1_ps(k.lambda_grad);
  const __m256 ldisp = _mm256_set1_ps(k.lambda_disp), outside = _mm256_set1_ps(k.outside_cost);
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  alignas(32) int offset[kSimdBlock];
  alignas(32) float frac[kSimdBlock];
  __m256 acc_lower = zero, acc_upper = zero;
  for (int s = 0; s < w.count; s += kSimdBlock) {
    // d's match, as aggregateAvx2.
    const __m256 x = _mm256_loadu_ps(w.xs + s);
    const __m256 y = _mm256_loadu_ps(w.ys + s);
    const __m256 d = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(va, x), _mm256_mul_ps(vb, y)), vc);
    const __m256 xm_raw = _mm256_add_ps(x, _mm256_mul_ps(sign, d));
    const __m256 inside = _mm256_and_ps(_mm256_cmp_ps(xm_raw, zero, _CMP_GE_OQ),
                                        _mm256_cmp_ps(xm_raw, x_max, _CMP_LE_OQ));
    const __m256 xm = _mm256_min_ps(_mm256_max_ps(xm_raw, zero), x_clamp);
    const __m256i i0 = _mm256_cvttps_epi32(xm);
    _mm256_store_ps(frac, _mm256_sub_ps(xm, _mm256_cvtepi32_ps(i0)));
    const __m256i row = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(w.texel_row + s));
    _mm256_store_si256(reinterpret_cast<__m256i*>(offset),
                       _mm256_add_epi32(row, _mm256_slli_epi32(i0, 3)));
    // own - m at d -+ h: own - m +- sign h (t1 - t0), on the interval of d's match.
    __m256 dk_lower[kSimdBlock], dk_upper[kSimdBlock];
    const float* own = w.texels + s * kTexelFloats;
    for (int j = 0; j < kSimdBlock; ++j) {
      const float* t = k.other_texels + offset[j];
      const __m256 t0 = _mm256_load_ps(t);
      const __m256 slope = _mm256_sub_ps(_mm256_load_ps(t + kTexelFloats), t0);
      const __m256 m = _mm256_add_ps(t0, _mm256_mul_ps(_mm256_broadcast_ss(frac + j), slope));
      const __m256 diff = _mm256_sub_ps(_mm256_loadu_ps(own + j * kTexelFloats), m);
      const __m256 moved = _mm256_mul_ps(shift, slope);
      dk_lower[j] = _mm256_and_ps(abs_mask, _mm256_add_ps(diff, moved));
      dk_upper[j] = _mm256_and_ps(abs_mask, _mm256_sub_ps(diff, moved));
    }
    __m256 col_lower, grad_lower, col_upper, grad_upper;
    channelSums(dk_lower, col_lower, grad_lower);
    channelSums(dk_upper, col_upper, grad_upper);
    const __m256 rho_lower = _mm256_blendv_ps(
        outside,
        _mm256_add_ps(_mm256_mul_ps(alpha, _mm256_min_ps(col_lower, lcol)),
                      _mm256_mul_ps(beta, _mm256_min_ps(grad_lower, lgrad))),
        inside);
    const __m256 rho_upper = _mm256_blendv_ps(
        outside,
        _mm256_add_ps(_mm256_mul_ps(alpha, _mm256_min_ps(col_upper, lcol)),
                      _mm256_mul_ps(beta, _mm256_min_ps(grad_upper, lgrad))),
        inside);
    const __m256 prior = _mm256_loadu_ps(w.priors + s);
    const __m256 w_img = _mm256_loadu_ps(w.w_img + s), w_lidar = _mm256_loadu_ps(w.w_lidar + s);
    const __m256 lid_lower =
        _mm256_min_ps(_mm256_and_ps(abs_mask, _mm256_sub_ps(prior, _mm256_sub_ps(d, vh))), ldisp);
    const __m256 lid_upper =
        _mm256_min_ps(_mm256_and_ps(abs_mask, _mm256_sub_ps(prior, _mm256_add_ps(d, vh))), ldisp);
    acc_lower = _mm256_add_ps(acc_lower, _mm256_add_ps(_mm256_mul_ps(w_img, rho_lower),
                                                       _mm256_mul_ps(w_lidar, lid_lower)));
    acc_upper = _mm256_add_ps(acc_upper, _mm256_add_ps(_mm256_mul_ps(w_img, rho_upper),
                                                       _mm256_mul_ps(w_lidar, lid_upper)));
  }
  lower = w.constant + laneSum(acc_lower);
  upper = w.constant + laneSum(acc_upper);
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion

#else  // no AVX2 + FMA in this build (non-x86): never selected, see simd.cpp

namespace lidar_stereo_fusion {
namespace patchmatch {

const bool kAvx2KernelBuilt = false;

float aggregateAvx2(const KernelWindow& w, const KernelConstants&, float, float, float, float) {
  return w.constant;
}

int buildWindowAvx2(const KernelSelf&, int, int, const KernelWindowOut&, int& padded,
                    float& constant) {
  padded = 0;
  constant = 0.f;
  return 0;
}

void aggregateSidesAvx2(const KernelWindow& w, const KernelConstants&, float, float, float, float,
                        float& lower, float& upper) {
  lower = upper = w.constant;
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion

#endif
