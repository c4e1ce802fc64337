// PatchMatch: the plain-data interface of the AVX2 + FMA matching-cost kernel (cost_avx2.cpp).
//
// This header includes no Eigen, OpenCV or standard-library template: cost_avx2.cpp is compiled
// with -mavx2 -mfma, and any inline function it shared with the rest of the library could be
// emitted with AVX2 instructions and picked by the linker for baseline code.
#pragma once

namespace lidar_stereo_fusion {
namespace patchmatch {

/// Channels per pixel in ViewState::texels and per sample in WindowCache::texels:
/// B, G, R, 0, gx, gy, 0, 0 (colour 0..255, gradient of the grey image; 0 without gradient),
/// each in 16-bit fixed point with kTexelScale steps per unit (to 1/64; colours exactly without
/// image_smoothing; the nodes' differences, +- 2 255 64, and a difference moved by the sub-pixel
/// step stay within 16 bits): one sample's two interpolation nodes fill 256 bits.
constexpr int kTexelChannels = 8;
constexpr int kTexelScale = 64;
/// One texel, 16-byte aligned (std::vector<Texel> allocates with that alignment in C++17).
struct alignas(16) Texel {
  short v[kTexelChannels];
};
/// The match's texel between nodes t0 and t1 at fraction f in [0, 1), in both kernels:
/// m = t0 + ((t1 - t0) fq + 2^14) >> 15 per channel with fq = round(f 2^15) (at most 2^15 - 1),
/// as _mm256_mulhrs_epi16; the L1 sums of |own - m| are exact integers, turned into floats and
/// divided by kTexelScale through the constants (alpha / 64 times min(L1, 64 lambda_col), ...).
constexpr int kFracOne = 1 << 15;

/// Largest window radius [px] (PatchMatchParams::kMaxWindowRadius, the range of window_radius
/// in core/param_table.h), and so the most offsets per window axis: the kernels' stack buffers.
constexpr int kMaxWindowRadius = 50;
constexpr int kMaxWindowOffsets = 2 * kMaxWindowRadius + 1;

/// Samples per SIMD block; WindowCache arrays are padded with zero-weight samples to a multiple.
constexpr int kSimdBlock = 8;

/// One pixel's window as the kernel reads it (structure of arrays, `count` a multiple of 8).
struct KernelWindow {
  const float* xs;       ///< sample x [px]
  const float* ys;       ///< sample y [px]
  const float* w_img;    ///< w(p, p') times the image term's factor of phi (0: padding)
  const float* w_lidar;  ///< w(p, p') times the LiDAR term's factor of phi
  const float* priors;   ///< prior disparity [px] (0: none)
  const short* texels;   ///< the sample's own texel, kTexelChannels per sample
  const int* texel_row;  ///< start of the sample's row in the other view's texels [shorts]
  int count;             ///< samples incl. padding, a multiple of kSimdBlock
  int real_count;        ///< samples without the padding
  float constant;        ///< plane-independent part of C
};

/// The other view and the cost's constants (cost.h).
struct KernelConstants {
  const short* other_texels;  ///< the other view, kTexelChannels per pixel, row-major
  float x_max;                ///< width - 1 [px]
  float x_clamp;              ///< largest x of the left interpolation node, < x_max
  float sign;                 ///< match of x at x + sign * d
  /// alpha and beta divided by kTexelScale, lambda_col and lambda_grad multiplied by it (the
  /// L1 sums are in texel units); lambda_disp [px]; the image term of a match outside the image.
  float alpha, beta, lambda_col, lambda_grad, lambda_disp, outside_cost;
};

/// What building a window reads from its own view and the cost's parameters (cost.h).
struct KernelSelf {
  const short* texels;         ///< the view's texels, kTexelChannels per pixel, row-major
  const float* prior;          ///< prior disparity [px] (nullptr: no prior term)
  const float* trust;          ///< the prior's weight [0, 1] (nullptr iff prior is)
  int prior_step, trust_step;  ///< row steps [floats]
  int width, height;
  int other_texel_stride;  ///< shorts per row of the other view's texels
  const int* offsets;      ///< window offsets in x and y [px]
  int offset_count;
  /// Row i of the window holds the columns [row_first[i], row_end[i]) (WindowRows, cost.h).
  const int *row_first, *row_end;
  int sample_count;         ///< samples of a window wholly inside the image
  const float* weight_lut;  ///< w by L1 colour distance times lut_scale
  int lut_size;
  float lut_scale;  ///< LUT entries per unit of RGB L1 distance
  bool weighted;    ///< confidence-weighted phi (else the paper's)
  float gamma, img_norm, lambda_disp;
  /// The samples of a window wholly inside the image, in the window's order and padded to a
  /// multiple of kSimdBlock with the first sample, as offsets from the centre: dx, dy [px], dy
  /// times other_texel_stride, the texel's [shorts] and the pixel's (prior and trust; nullptr
  /// when their row steps are not the width: then every window takes the general path).
  const float *interior_dx, *interior_dy;
  const int *interior_row, *interior_texel, *interior_pixel;
};

/// Where a window is written: WindowCache's arrays, with room for the padding.
struct KernelWindowOut {
  float *xs, *ys, *w_img, *w_lidar, *priors;
  short* texels;
  int* texel_row;
};

/// The window of pixel (px, py), as MatchingCost::buildWindow, padded to a multiple of
/// kSimdBlock with zero-weight samples. Returns the number of real samples; `padded` and
/// `constant` receive the padded count and the plane-independent part of C.
int buildWindowAvx2(const KernelSelf& s, int px, int py, const KernelWindowOut& out, int& padded,
                    float& constant);

/// True when cost_avx2.cpp was compiled with AVX2 + FMA (x86 builds).
extern const bool kAvx2KernelBuilt;

/// Summation order of C, shared by both paths so that they return the same float: sample k's
/// term is added to lane k % kSimdBlock; C = constant + ((l0 + l4) + (l2 + l6)) + ((l1 + l5) +
/// (l3 + l7)); the bound is checked after every second block of kSimdBlock samples (a partial
/// sum only grows, so checking never changes which plane wins; every block, the check would cost
/// more than the blocks it saves).
/// C(p, xi) for the plane d = a x + b y + c over the window; stops once the partial sum is
/// >= bound (returning it), else returns the full sum. Call only when the CPU has AVX2 + FMA.
float aggregateAvx2(const KernelWindow& w, const KernelConstants& k, float a, float b, float c,
                    float bound);

/// The costs of the planes d - h and d + h (c -+ h), each sample's match interpolated on the
/// interval of d's match (linear in the shift, exact where the other view is linear there), in
/// one pass: MatchingCost::aggregateSides; shift_q = round(sign h 2^15), the match's move in
/// the fixed point of the fraction. Summed like C, no bound. Call only with AVX2 + FMA.
void aggregateSidesAvx2(const KernelWindow& w, const KernelConstants& k, float a, float b, float c,
                        float h, int shift_q, float& lower, float& upper);

/// True when cost_avx512.cpp was compiled with AVX-512 F, BW, VL and DQ (x86 builds).
extern const bool kAvx512KernelBuilt;

/// aggregateAvx2 and aggregateSidesAvx2 with AVX-512 (16 samples per step), bit-identical to
/// them. Call only where the CPU has AVX-512 F, BW, VL, DQ and the operating system keeps the
/// 512-bit registers (simd.h).
float aggregateAvx512(const KernelWindow& w, const KernelConstants& k, float a, float b, float c,
                      float bound);
void aggregateSidesAvx512(const KernelWindow& w, const KernelConstants& k, float a, float b,
                          float c, float h, int shift_q, float& lower, float& upper);

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
