// PatchMatch: the plain-data interface of the AVX2 + FMA matching-cost kernel (cost_avx2.cpp).
//
// This header includes no Eigen, OpenCV or standard-library template: cost_avx2.cpp is compiled
// with -mavx2 -mfma, and any inline function it shared with the rest of the library could be
// emitted with AVX2 instructions and picked by the linker for baseline code.
#pragma once

namespace lidar_stereo_fusion {
namespace patchmatch {

/// Floats per pixel in ViewState::texels and per sample in WindowCache::texels:
/// B, G, R, 0, gx, gy, 0, 0 (colour 0..255, gradient of the grey image; 0 without gradient).
constexpr int kTexelFloats = 8;

/// One texel, 32-byte aligned so that the kernel's 8-float loads never straddle a cache line
/// (std::vector<Texel> allocates with that alignment in C++17).
struct alignas(32) Texel {
  float v[kTexelFloats];
};

/// Samples per SIMD block; WindowCache arrays are padded with zero-weight samples to a multiple.
constexpr int kSimdBlock = 8;

/// One pixel's window as the kernel reads it (structure of arrays, `count` a multiple of 8).
struct KernelWindow {
  const float* xs;       ///< sample x [px]
  const float* ys;       ///< sample y [px]
  const float* w_img;    ///< w(p, p') times the image term's factor of phi (0: padding)
  const float* w_lidar;  ///< w(p, p') times the LiDAR term's factor of phi
  const float* priors;   ///< prior disparity [px] (0: none)
  const float* texels;   ///< the sample's own texel, kTexelFloats per sample
  const int* texel_row;  ///< start of the sample's row in the other view's texels [floats]
  int count;             ///< samples incl. padding, a multiple of kSimdBlock
  int real_count;        ///< samples without the padding
  float constant;        ///< plane-independent part of C
};

/// The other view and the cost's constants (cost.h).
struct KernelConstants {
  const float* other_texels;  ///< the other view, kTexelFloats per pixel, row-major
  float x_max;                ///< width - 1 [px]
  float x_clamp;              ///< largest x of the left interpolation node, < x_max
  float sign;                 ///< match of x at x + sign * d
  float alpha, beta, lambda_col, lambda_grad, lambda_disp, outside_cost;
};

/// What building a window reads from its own view and the cost's parameters (cost.h).
struct KernelSelf {
  const float* texels;         ///< the view's texels, kTexelFloats per pixel, row-major
  const float* prior;          ///< prior disparity [px] (nullptr: no prior term)
  const float* trust;          ///< the prior's weight [0, 1] (nullptr iff prior is)
  int prior_step, trust_step;  ///< row steps [floats]
  int width, height;
  int other_texel_stride;  ///< floats per row of the other view's texels
  const int* offsets;      ///< window offsets in x and y [px]
  int offset_count;
  const float* weight_lut;  ///< w by L1 colour distance times lut_scale
  int lut_size;
  float lut_scale;
  bool weighted;  ///< confidence-weighted phi (else the paper's)
  float gamma, img_norm, lambda_disp;
};

/// Where a window is written: WindowCache's arrays, with room for the padding.
struct KernelWindowOut {
  float *xs, *ys, *w_img, *w_lidar, *priors, *texels;
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
/// (l3 + l7)); the bound is checked after every block of kSimdBlock samples (a partial sum only
/// grows, so checking never changes which plane wins).
/// C(p, xi) for the plane d = a x + b y + c over the window; stops once the partial sum is
/// >= bound (returning it), else returns the full sum. Call only when the CPU has AVX2 + FMA.
float aggregateAvx2(const KernelWindow& w, const KernelConstants& k, float a, float b, float c,
                    float bound);

/// The costs of the planes d - h and d + h (c -+ h), each sample's match interpolated on the
/// interval of d's match (linear in the shift, exact where the other view is linear there), in
/// one pass: MatchingCost::aggregateSides. Summed like C, no bound. Call only with AVX2 + FMA.
void aggregateSidesAvx2(const KernelWindow& w, const KernelConstants& k, float a, float b,
                        float c, float h, float& lower, float& upper);

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
