// PatchMatch: the matching cost C(p, xi) (cost.h) and its window with AVX2, 8 window samples at
// a time. Compiled with -mavx2 -mfma -ffp-contract=off (CMakeLists.txt) and run only where the CPU
// has both (simd.h); no FMA instruction is used, so that results stay the baseline's.
// Includes nothing but intrinsics and the plain-data kernel interface (see cost_kernel.h).
//
// Per block of 8 samples: the disparity d, the match x_q and its interpolation fraction are
// computed as float vectors. The texels are 16-bit fixed point (B, G, R, 0, gx, gy, 0, 0), so a
// sample's two nodes around x_q are one 256-bit load, and two samples (p and p + 4) share each
// integer operation: interpolation (mulhrs), difference with the own texel, absolute value, and
// the channel-pair sums; two horizontal adds and a shuffle turn the four pairs into the colour
// L1 and gradient L1 of the 8 samples, exact integers. From there every float operation is the
// baseline's, in its order (no FMA contraction, the lanes and their reduction as in
// cost_kernel.h), so both paths give bit-identical costs and PatchMatch results do not depend on
// the CPU.
#include "lidar_stereo_fusion/core/patchmatch/cost_kernel.h"

#if defined(__AVX2__) && defined(__FMA__)

#include <immintrin.h>

namespace lidar_stereo_fusion {
namespace patchmatch {

const bool kAvx2KernelBuilt = true;

namespace {

/// Offsets per window axis at most: every pixel of the largest window (stride 1).
constexpr int kMaxOffsets = kMaxWindowOffsets;

/// The 8 samples of a block are handled as the pairs (p, p + 4), p < 4: the lower 128 bits hold
/// sample p, the upper sample p + 4.
constexpr int kPairs = kSimdBlock / 2;

/// Calls f(PairIndex<p>()) for the pairs p < pairs that hold a real sample (p < kPairs; the
/// shuffles that pick a pair's lanes take p as an immediate); the callers' sums start at zero for
/// the others. Only a window's last block has pairs of padding alone; their zero-weight terms are
/// 0 either way, so skipping them changes no float (a 7 x 7 window's last block holds 1 sample).
template <int p>
struct PairIndex {
  static constexpr int value = p;
};
template <class F>
inline void forRealPairs(int pairs, F&& f) {
  f(PairIndex<0>());  // a block holds at least one real sample
  if (pairs > 1) f(PairIndex<1>());
  if (pairs > 2) f(PairIndex<2>());
  if (pairs > 3) f(PairIndex<3>());
}

/// The pairs of the block starting at sample s that hold a real sample (pair p holds p and
/// p + kPairs).
inline int realPairs(int real_count, int s) {
  const int left = real_count - s;
  return left < kPairs ? left : kPairs;
}

/// [v_p | v_{p + 4}] of the 16-byte entries v of a block (texels).
inline __m256i pairOf(const short* v, int p) {
  return _mm256_inserti128_si256(
      _mm256_castsi128_si256(_mm_load_si128(reinterpret_cast<const __m128i*>(v + p * 8))),
      _mm_load_si128(reinterpret_cast<const __m128i*>(v + (p + kPairs) * 8)), 1);
}

/// Pair p's fractions, each repeated over its 8 channels, from the block's 8 fractions (16-bit)
/// in both 128-bit halves.
inline __m256i pairFraction(__m256i fractions, int p) {
  const char lo = static_cast<char>(2 * p), hi = static_cast<char>(2 * p + 1);
  const char lo4 = static_cast<char>(2 * p + 8), hi4 = static_cast<char>(2 * p + 9);
  const __m256i select =
      _mm256_setr_epi8(lo, hi, lo, hi, lo, hi, lo, hi, lo, hi, lo, hi, lo, hi, lo, hi, lo4, hi4,
                       lo4, hi4, lo4, hi4, lo4, hi4, lo4, hi4, lo4, hi4, lo4, hi4, lo4, hi4);
  return _mm256_shuffle_epi8(fractions, select);
}

/// The colour L1 (out: col) and gradient L1 (out: grad) of the 8 samples, as floats in texel
/// units, from each pair's |differences| summed by channel pairs (madd with ones):
/// (B + G, R + 0, gx + gy, 0 + 0) per sample.
inline void channelSums(const __m256i* pair_sums, __m256& col, __m256& grad) {
  // Per 128-bit half: (col, grad) of samples 0, 1 | 4, 5 and of 2, 3 | 6, 7.
  const __m256 a = _mm256_castsi256_ps(_mm256_hadd_epi32(pair_sums[0], pair_sums[1]));
  const __m256 b = _mm256_castsi256_ps(_mm256_hadd_epi32(pair_sums[2], pair_sums[3]));
  col = _mm256_cvtepi32_ps(_mm256_castps_si256(_mm256_shuffle_ps(a, b, 0x88)));   // 0..3 | 4..7
  grad = _mm256_cvtepi32_ps(_mm256_castps_si256(_mm256_shuffle_ps(a, b, 0xDD)));  // the same
}

/// ((l0 + l4) + (l2 + l6)) + ((l1 + l5) + (l3 + l7)) of the 8 lanes (cost_kernel.h's order).
inline float laneSum(__m256 v) {
  const __m128 s4 = _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  const __m128 s2 = _mm_add_ps(s4, _mm_movehl_ps(s4, s4));
  return _mm_cvtss_f32(_mm_add_ss(s2, _mm_shuffle_ps(s2, s2, 1)));
}

/// The plane's match of a block of 8 samples: d, the mask of matches inside the image, the left
/// nodes' offsets in the other view's texels (written to `node`) and the 8 fractions in fixed
/// point (16-bit, in both 128-bit halves), as cost.cpp's matchOf.
struct BlockMatch {
  __m256 d, inside;
  __m256i fractions;
};

inline BlockMatch matchBlock(const KernelWindow& w, const KernelConstants& k, int s, __m256 va,
                             __m256 vb, __m256 vc, int* node) {
  const __m256 zero = _mm256_setzero_ps();
  const __m256 x = _mm256_loadu_ps(w.xs + s);
  const __m256 y = _mm256_loadu_ps(w.ys + s);
  BlockMatch m;
  m.d = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(va, x), _mm256_mul_ps(vb, y)), vc);
  const __m256 xm_raw = _mm256_add_ps(x, _mm256_mul_ps(_mm256_set1_ps(k.sign), m.d));
  m.inside = _mm256_and_ps(_mm256_cmp_ps(xm_raw, zero, _CMP_GE_OQ),
                           _mm256_cmp_ps(xm_raw, _mm256_set1_ps(k.x_max), _CMP_LE_OQ));
  const __m256 xm = _mm256_min_ps(_mm256_max_ps(xm_raw, zero), _mm256_set1_ps(k.x_clamp));
  const __m256i i0 = _mm256_cvttps_epi32(xm);
  const __m256 f = _mm256_sub_ps(xm, _mm256_cvtepi32_ps(i0));
  // Rounded to nearest even, saturated at 2^15 - 1 by the pack.
  const __m256i f32 = _mm256_cvtps_epi32(_mm256_mul_ps(f, _mm256_set1_ps(kFracOne)));
  m.fractions = _mm256_broadcastsi128_si256(
      _mm_packs_epi32(_mm256_castsi256_si128(f32), _mm256_extracti128_si256(f32, 1)));
  const __m256i row = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(w.texel_row + s));
  _mm256_store_si256(reinterpret_cast<__m256i*>(node),
                     _mm256_add_epi32(row, _mm256_slli_epi32(i0, 3)));  // 8 shorts per texel
  return m;
}

/// Pair p's |own - m| per channel, m interpolated between the nodes, and the nodes' difference
/// (out: slope) for the sub-pixel step.
inline __m256i pairDifference(const short* other, const int* node, const short* own, int p,
                              __m256i fractions, __m256i& slope, __m256i& diff) {
  const __m256i a = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(other + node[p]));
  const __m256i b = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(other + node[p + kPairs]));
  const __m256i t0 = _mm256_permute2x128_si256(a, b, 0x20);
  slope = _mm256_sub_epi16(_mm256_permute2x128_si256(a, b, 0x31), t0);
  const __m256i m = _mm256_add_epi16(t0, _mm256_mulhrs_epi16(slope, pairFraction(fractions, p)));
  diff = _mm256_sub_epi16(pairOf(own, p), m);
  return _mm256_abs_epi16(diff);
}

/// The image term of 8 samples: alpha min(col, lambda_col) + beta min(grad, lambda_grad), or the
/// outside cost where the match left the image.
inline __m256 imageTerm(const KernelConstants& k, __m256 col, __m256 grad, __m256 inside) {
  const __m256 rho = _mm256_add_ps(
      _mm256_mul_ps(_mm256_set1_ps(k.alpha), _mm256_min_ps(col, _mm256_set1_ps(k.lambda_col))),
      _mm256_mul_ps(_mm256_set1_ps(k.beta), _mm256_min_ps(grad, _mm256_set1_ps(k.lambda_grad))));
  return _mm256_blendv_ps(_mm256_set1_ps(k.outside_cost), rho, inside);
}

/// Entries [from, to) of the window: zero-weight padding at the first sample's position, with a
/// zero texel, prior and trust (parked in w_lidar).
void writePadding(const KernelWindowOut& out, int from, int to) {
  for (int j = from; j < to; ++j) {
    out.xs[j] = out.xs[0];
    out.ys[j] = out.ys[0];
    out.texel_row[j] = out.texel_row[0];
    _mm_store_si128(reinterpret_cast<__m128i*>(out.texels + j * kTexelChannels),
                    _mm_setzero_si128());
    out.priors[j] = 0.f;
    out.w_lidar[j] = 0.f;
  }
}

/// Pass 1 of buildWindowAvx2: positions, texels and priors of the samples inside the image, then
/// the padding; the trust is parked in w_lidar. Returns the number of real samples. Per row, the
/// positions are written 8 at a time (the arrays have kSimdBlock entries of room; what a row
/// writes beyond its samples is overwritten by the next row or the padding).
int gatherSamples(const KernelSelf& s, int px, int py, const KernelWindowOut& out, int padded_max) {
  // The offsets increase, so the columns inside the image are one range [j0, j1), and a row's
  // samples inside it one range [a, b) (the window's row [row_first, row_end) cut by it).
  int j0 = 0, j1 = s.offset_count;
  while (j0 < j1 && px + s.offsets[j0] < 0) ++j0;
  while (j1 > j0 && px + s.offsets[j1 - 1] >= s.width) --j1;
  // Locals, not s's members: the stores below could alias them as far as the compiler knows.
  const short* const texels = s.texels;
  const float* const prior = s.prior;
  const float* const trust = s.trust;
  alignas(32) float xcol[kMaxOffsets + kSimdBlock];
  for (int j = 0; j < s.offset_count + kSimdBlock; ++j) {
    xcol[j] = j < s.offset_count ? static_cast<float>(px + s.offsets[j]) : 0.f;
  }
  int k = 0;
  for (int i = 0; i < s.offset_count; ++i) {
    const int y = py + s.offsets[i];
    if (y < 0 || y >= s.height) continue;
    const int a = j0 > s.row_first[i] ? j0 : s.row_first[i];
    const int b = j1 < s.row_end[i] ? j1 : s.row_end[i];
    const int m = b - a;
    if (m <= 0) continue;
    const int* const cols = s.offsets + a;
    const __m256 fy = _mm256_set1_ps(static_cast<float>(y));
    const __m256i row = _mm256_set1_epi32(y * s.other_texel_stride);
    for (int q = 0; q < m; q += kSimdBlock) {
      _mm256_storeu_ps(out.xs + k + q, _mm256_loadu_ps(xcol + a + q));
      _mm256_storeu_ps(out.ys + k + q, fy);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out.texel_row + k + q), row);
    }
    const short* texel_row = texels + (static_cast<long>(y) * s.width + px) * kTexelChannels;
    __m128i* own = reinterpret_cast<__m128i*>(out.texels + k * kTexelChannels);
    const auto copy_texel = [&](int j, int col) {
      _mm_store_si128(
          own + j,
          _mm_load_si128(reinterpret_cast<const __m128i*>(texel_row + col * kTexelChannels)));
    };
    float* priors = out.priors + k;
    float* trusts = out.w_lidar + k;
    if (prior != nullptr) {  // one pass over the columns for texel, prior and trust
      const float* prior_row = prior + static_cast<long>(y) * s.prior_step + px;
      const float* trust_row = trust + static_cast<long>(y) * s.trust_step + px;
      for (int j = 0; j < m; ++j) {
        const int col = cols[j];
        copy_texel(j, col);
        priors[j] = prior_row[col];
        trusts[j] = trust_row[col];
      }
    } else {
      for (int j = 0; j < m; ++j) {
        copy_texel(j, cols[j]);
        priors[j] = trusts[j] = 0.f;
      }
    }
    k += m;
  }
  writePadding(out, k, padded_max);
  return k;
}

/// The RGB L1 distance to the centre of the 8 samples whose texels are in `pairs` ([t_p |
/// t_{p + 4}], pairOf), in texel units (exact integers); pairs beyond `real_pairs` count 0.
inline __m256 colourDistance(const __m256i* pairs, int real_pairs, __m256i center) {
  const __m256i colour = _mm256_setr_epi16(1, 1, 1, 0, 0, 0, 0, 0, 1, 1, 1, 0, 0, 0, 0, 0);
  __m256i pair_sums[kPairs] = {};
  forRealPairs(real_pairs, [&](auto pair) {
    constexpr int p = decltype(pair)::value;
    pair_sums[p] = _mm256_madd_epi16(_mm256_abs_epi16(_mm256_sub_epi16(pairs[p], center)), colour);
  });
  __m256 l1, unused;
  channelSums(pair_sums, l1, unused);
  return l1;
}

/// w_img and w_lidar of the block of 8 samples starting at b, from their colour distance to the
/// centre (texel units) and the prior's trust; the paper's plane-independent terms are added to
/// `constant`. Samples from `count` on are padding: weight 0.
inline void blockWeights(const KernelSelf& s, const KernelWindowOut& out, int b, int count,
                         __m256 l1, __m256 trust, float& constant) {
  // w = LUT[min(lut_size - 1, int(l1 * lut_step))] (l1 >= 0), 0 on the padding. Eight scalar
  // loads, not a gather instruction: with the microcode mitigation of gather data sampling on
  // current Intel CPUs a gather costs a fifth of the whole window build.
  const __m256 lut_step = _mm256_set1_ps(s.lut_scale / static_cast<float>(kTexelScale));
  const __m256 lut_last = _mm256_set1_ps(static_cast<float>(s.lut_size - 1));
  alignas(32) int lut_index[kSimdBlock];
  _mm256_store_si256(reinterpret_cast<__m256i*>(lut_index),
                     _mm256_cvttps_epi32(_mm256_min_ps(_mm256_mul_ps(l1, lut_step), lut_last)));
  const float* lut = s.weight_lut;
  const __m256 looked_up =
      _mm256_setr_ps(lut[lut_index[0]], lut[lut_index[1]], lut[lut_index[2]], lut[lut_index[3]],
                     lut[lut_index[4]], lut[lut_index[5]], lut[lut_index[6]], lut[lut_index[7]]);
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256 valid = _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(count - b), lane));
  const __m256 w = _mm256_and_ps(valid, looked_up);
  const __m256 gamma = _mm256_set1_ps(s.gamma);
  if (s.weighted) {  // phi = (1 - kappa) / (alpha + beta) rho_img + kappa rho_lid
    const __m256 kappa = _mm256_mul_ps(gamma, trust);
    _mm256_storeu_ps(out.w_img + b,
                     _mm256_mul_ps(_mm256_mul_ps(w, _mm256_sub_ps(_mm256_set1_ps(1.f), kappa)),
                                   _mm256_set1_ps(s.img_norm)));
    _mm256_storeu_ps(out.w_lidar + b, _mm256_mul_ps(w, kappa));
    return;
  }
  // The paper: phi = rho_img + gamma rho_lid, or + gamma lambda_disp without a prior value.
  const __m256 has_value = _mm256_cmp_ps(trust, _mm256_setzero_ps(), _CMP_GT_OQ);
  const __m256 w_gamma = _mm256_mul_ps(w, gamma);
  _mm256_storeu_ps(out.w_img + b, w);
  _mm256_storeu_ps(out.w_lidar + b, _mm256_and_ps(has_value, w_gamma));
  if (s.prior == nullptr) return;
  alignas(32) float empty_cost[kSimdBlock];
  const __m256 empty = _mm256_mul_ps(w_gamma, _mm256_set1_ps(s.lambda_disp));
  _mm256_store_ps(empty_cost, _mm256_andnot_ps(has_value, empty));
  for (int j = 0; j < kSimdBlock; ++j) constant += empty_cost[j];  // the scalar code's order
}

/// The 8 values at `base` + idx[0..7].
inline __m256 pick8(const float* base, const int* idx) {
  return _mm256_setr_ps(base[idx[0]], base[idx[1]], base[idx[2]], base[idx[3]], base[idx[4]],
                        base[idx[5]], base[idx[6]], base[idx[7]]);
}

/// The window of a pixel whose samples are all inside the image, from the fixed offsets of
/// KernelSelf's interior window, a block of 8 samples at a time in one pass: the same entries
/// as gatherSamples and the weights' pass (the padding too, by writePadding).
void interiorWindow(const KernelSelf& s, int px, int py, const KernelWindowOut& out, int count,
                    int padded, __m256i center, float& constant) {
  const long centre = static_cast<long>(py) * s.width + px;
  const short* texels = s.texels + centre * kTexelChannels;
  const float* prior = s.prior != nullptr ? s.prior + centre : nullptr;
  const float* trust = s.prior != nullptr ? s.trust + centre : nullptr;
  const __m256 fx = _mm256_set1_ps(static_cast<float>(px));
  const __m256 fy = _mm256_set1_ps(static_cast<float>(py));
  const __m256i row = _mm256_set1_epi32(py * s.other_texel_stride);
  for (int b = 0; b < padded; b += kSimdBlock) {
    _mm256_storeu_ps(out.xs + b, _mm256_add_ps(fx, _mm256_loadu_ps(s.interior_dx + b)));
    _mm256_storeu_ps(out.ys + b, _mm256_add_ps(fy, _mm256_loadu_ps(s.interior_dy + b)));
    _mm256_storeu_si256(
        reinterpret_cast<__m256i*>(out.texel_row + b),
        _mm256_add_epi32(row,
                         _mm256_loadu_si256(reinterpret_cast<const __m256i*>(s.interior_row + b))));
    const int* at = s.interior_texel + b;
    __m128i* own = reinterpret_cast<__m128i*>(out.texels + b * kTexelChannels);
    __m256i pairs[kPairs];
    for (int p = 0; p < kPairs; ++p) {
      const __m128i lo = _mm_load_si128(reinterpret_cast<const __m128i*>(texels + at[p]));
      const __m128i hi = _mm_load_si128(reinterpret_cast<const __m128i*>(texels + at[p + kPairs]));
      _mm_store_si128(own + p, lo);
      _mm_store_si128(own + p + kPairs, hi);
      pairs[p] = _mm256_inserti128_si256(_mm256_castsi128_si256(lo), hi, 1);
    }
    const __m256 l1 = colourDistance(pairs, realPairs(count, b), center);
    __m256 trusts = _mm256_setzero_ps();
    if (prior != nullptr) {
      const int* pixel = s.interior_pixel + b;
      _mm256_storeu_ps(out.priors + b, pick8(prior, pixel));
      trusts = pick8(trust, pixel);
    } else {
      _mm256_storeu_ps(out.priors + b, _mm256_setzero_ps());
    }
    blockWeights(s, out, b, count, l1, trusts, constant);
  }
  // The padding's weights are already 0; its texel and prior become 0 too, as gatherSamples'.
  writePadding(out, count, padded);
}

}  // namespace

int buildWindowAvx2(const KernelSelf& s, int px, int py, const KernelWindowOut& out, int& padded,
                    float& constant) {
  const int n = s.sample_count;
  const int padded_max = (n + kSimdBlock - 1) / kSimdBlock * kSimdBlock;
  constant = 0.f;
  const __m128i center128 = _mm_load_si128(reinterpret_cast<const __m128i*>(
      s.texels + (static_cast<long>(py) * s.width + px) * kTexelChannels));
  const __m256i center = _mm256_broadcastsi128_si256(center128);
  const int first = s.offsets[0], last = s.offsets[s.offset_count - 1];
  if ((s.prior == nullptr || s.interior_pixel != nullptr) && px + first >= 0 &&
      px + last < s.width && py + first >= 0 && py + last < s.height) {
    padded = padded_max;
    interiorWindow(s, px, py, out, n, padded, center, constant);
    return n;
  }
  const int count = gatherSamples(s, px, py, out, padded_max);
  padded = (count + kSimdBlock - 1) / kSimdBlock * kSimdBlock;
  for (int b = 0; b < padded; b += kSimdBlock) {
    __m256i pairs[kPairs];
    for (int p = 0; p < kPairs; ++p) pairs[p] = pairOf(out.texels + b * kTexelChannels, p);
    const __m256 l1 = colourDistance(pairs, realPairs(count, b), center);
    blockWeights(s, out, b, count, l1, _mm256_loadu_ps(out.w_lidar + b), constant);
  }
  return count;
}

float aggregateAvx2(const KernelWindow& w, const KernelConstants& k, float a, float b, float c,
                    float bound) {
  if (w.constant >= bound) return w.constant;
  const __m256 va = _mm256_set1_ps(a), vb = _mm256_set1_ps(b), vc = _mm256_set1_ps(c);
  const __m256 ldisp = _mm256_set1_ps(k.lambda_disp);
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  const __m256i ones = _mm256_set1_epi16(1);
  alignas(32) int node[kSimdBlock];
  __m256 acc = _mm256_setzero_ps();  // lane j sums the samples j, j + 8, ... (the baseline's)
  for (int s = 0; s < w.count; s += kSimdBlock) {
    // Each float operation as the baseline code does it (no FMA; -ffp-contract=off here).
    const BlockMatch m = matchBlock(w, k, s, va, vb, vc, node);
    const short* own = w.texels + s * kTexelChannels;
    __m256i pair_sums[kPairs] = {};
    forRealPairs(realPairs(w.real_count, s), [&](auto pair) {
      constexpr int p = decltype(pair)::value;
      __m256i slope, diff;
      const __m256i l1 = pairDifference(k.other_texels, node, own, p, m.fractions, slope, diff);
      pair_sums[p] = _mm256_madd_epi16(l1, ones);
    });
    __m256 col, grad;
    channelSums(pair_sums, col, grad);
    const __m256 rho_img = imageTerm(k, col, grad, m.inside);
    const __m256 lid = _mm256_and_ps(abs_mask, _mm256_sub_ps(_mm256_loadu_ps(w.priors + s), m.d));
    const __m256 rho_lid = _mm256_min_ps(lid, ldisp);
    // Padding samples have zero weights: their term is exactly 0 and leaves the lanes unchanged.
    acc = _mm256_add_ps(acc, _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(w.w_img + s), rho_img),
                                           _mm256_mul_ps(_mm256_loadu_ps(w.w_lidar + s), rho_lid)));
    // The bound is checked after every second block, as the baseline does: the same exit, the
    // same float.
    if ((s / kSimdBlock) % 2 == 1) {
      const float sum = w.constant + laneSum(acc);
      if (sum >= bound) return sum;
    }
  }
  return w.constant + laneSum(acc);
}

void aggregateSidesAvx2(const KernelWindow& w, const KernelConstants& k, float a, float b, float c,
                        float h, int shift_q, float& lower, float& upper) {
  const __m256 va = _mm256_set1_ps(a), vb = _mm256_set1_ps(b), vc = _mm256_set1_ps(c);
  const __m256 vh = _mm256_set1_ps(h), ldisp = _mm256_set1_ps(k.lambda_disp);
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  const __m256i ones = _mm256_set1_epi16(1), shift = _mm256_set1_epi16(static_cast<short>(shift_q));
  alignas(32) int node[kSimdBlock];
  __m256 acc_lower = _mm256_setzero_ps(), acc_upper = _mm256_setzero_ps();
  for (int s = 0; s < w.count; s += kSimdBlock) {
    const BlockMatch m = matchBlock(w, k, s, va, vb, vc, node);
    const short* own = w.texels + s * kTexelChannels;
    // own - m at d -+ h: own - m +- the nodes' difference times the shift, on d's interval.
    __m256i sums_lower[kPairs] = {}, sums_upper[kPairs] = {};
    forRealPairs(realPairs(w.real_count, s), [&](auto pair) {
      constexpr int p = decltype(pair)::value;
      __m256i slope, diff;
      pairDifference(k.other_texels, node, own, p, m.fractions, slope, diff);
      const __m256i moved = _mm256_mulhrs_epi16(slope, shift);
      sums_lower[p] = _mm256_madd_epi16(_mm256_abs_epi16(_mm256_add_epi16(diff, moved)), ones);
      sums_upper[p] = _mm256_madd_epi16(_mm256_abs_epi16(_mm256_sub_epi16(diff, moved)), ones);
    });
    __m256 col_lower, grad_lower, col_upper, grad_upper;
    channelSums(sums_lower, col_lower, grad_lower);
    channelSums(sums_upper, col_upper, grad_upper);
    const __m256 rho_lower = imageTerm(k, col_lower, grad_lower, m.inside);
    const __m256 rho_upper = imageTerm(k, col_upper, grad_upper, m.inside);
    const __m256 prior = _mm256_loadu_ps(w.priors + s);
    const __m256 w_img = _mm256_loadu_ps(w.w_img + s), w_lidar = _mm256_loadu_ps(w.w_lidar + s);
    const __m256 lid_lower =
        _mm256_min_ps(_mm256_and_ps(abs_mask, _mm256_sub_ps(prior, _mm256_sub_ps(m.d, vh))), ldisp);
    const __m256 lid_upper =
        _mm256_min_ps(_mm256_and_ps(abs_mask, _mm256_sub_ps(prior, _mm256_add_ps(m.d, vh))), ldisp);
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
                        int, float& lower, float& upper) {
  lower = upper = w.constant;
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion

#endif
