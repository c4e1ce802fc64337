// PatchMatch: the aggregated matching cost C(p, xi) of a plane over the support window
// (METHOD.md section 3), with the adaptive support weight w and the per-sample cost phi named.
//
//   C(p, xi) = sum_{p' in W_p} w(p, p') phi(p', q),   q = p' + s d_xi(p') in the other view
//   w(p, p') = exp(-|I_p - I_p'|_1 / delta)
//   rho_img  = alpha min(|I_p' - I_q|_1, lambda_col) + beta min(|grad I_p' - grad I_q|_1,
//   lambda_grad) rho_lid  = min(|Pi(p') - d_xi(p')|, lambda_disp)
//
// Two readings of phi:
//  * the paper (confidence_weighting = false): phi = rho_img + gamma rho_lid where the prior has a
//    value, rho_img + gamma lambda_disp where it has none (a constant: it never rewards a plane);
//  * confidence-weighted (the default): with kappa = gamma c(p'), c the prior's confidence
//    (prior_confidence.h, 0 without a prior),
//      phi = (1 - kappa) / (alpha + beta) rho_img + kappa rho_lid.
//    Where the LiDAR is sure (c = 1) this is the paper's phi; where it fades the image term is
//    renormalised to full weight, so that with no LiDAR it is plain stereo (Bleyer et al.).
// A sample whose match falls outside the other image costs the colour/gradient truncations.
// Colours and gradients are read in 16-bit fixed point (cost_kernel.h: to 1/64, colours exactly
// without image_smoothing; I_q interpolated at q to 1/64), so that the AVX2 kernel handles two
// samples per operation.
#pragma once

#include <vector>

#include "lidar_stereo_fusion/core/patchmatch/cost_kernel.h"
#include "lidar_stereo_fusion/core/patchmatch/params.h"
#include "lidar_stereo_fusion/core/patchmatch/plane.h"
#include "lidar_stereo_fusion/core/patchmatch/view_state.h"

namespace lidar_stereo_fusion {
namespace patchmatch {

/// The window samples of one pixel in structure-of-arrays form, built once per pixel and shared by
/// every candidate plane. Arrays are sized once; `count` says how many entries are in use, and
/// the AVX2 kernel reads `padded` samples: the window padded to a multiple of kSimdBlock with
/// zero-weight samples.
struct WindowCache {
  std::vector<float> xs, ys;
  std::vector<float> w_img;    ///< w(p, p') times the image term's factor of phi
  std::vector<float> w_lidar;  ///< w(p, p') times the LiDAR term's factor of phi (0: no prior)
  std::vector<float> priors;
  std::vector<Texel> texels;   ///< the sample's own texel
  std::vector<int> texel_row;  ///< start of the sample's row in the other view's texels [shorts]
  float constant = 0.f;        ///< sum of the plane-independent terms (paper: empty prior)
  int count = 0;
  int padded = 0;  ///< count rounded up to a multiple of kSimdBlock (AVX2 path)
  /// The window as the SIMD kernels read it, set by MatchingCost::buildWindow (pointers into the
  /// arrays above: valid until they are resized or the cache is copied).
  KernelWindow kernel{};
  void reserve(size_t n);
};

/// The window offsets used in x and in y, ascending: the multiples of `stride` within `radius`, or
/// with `dyadic` 0, +-stride, +-2 stride, +-4 stride, ... within `radius`.
std::vector<int> windowOffsets(int radius, int stride, bool dyadic);

/// The window's samples, row by row on the grid of `offsets` (windowOffsets): row i (dy =
/// offsets[i]) holds the columns j in [first[i], end[i]) (dx = offsets[j]). Square: every column
/// of every row; round: the samples with dx^2 + dy^2 <= radius^2 (a disc: each row an interval
/// around dx = 0, since the offsets ascend).
struct WindowRows {
  std::vector<int> first, end;
  int count = 0;  ///< samples in the window
};
WindowRows windowRows(const std::vector<int>& offsets, int radius, bool round);

/// The factors of phi for one window sample (the support weight w(p, p') folded in): the sample
/// costs w phi = image rho_img + lidar rho_lid + constant (see the two readings of phi above).
struct PhiWeights {
  float image;     ///< w times rho_img's factor
  float lidar;     ///< w times rho_lid's factor (0: no prior)
  float constant;  ///< the plane-independent part (the paper: gamma lambda_disp without a prior)
};

class MatchingCost {
 public:
  /// Uses the AVX2 kernels when params.simd_path is kAvx2, and the AVX-512 cost with the AVX2
  /// window when it is kAvx512. Keeps references to `params` and the views: they must outlive it.
  MatchingCost(const PatchMatchParams& params, const ViewState& self, const ViewState& other);

  /// w(p, p') for an RGB L1 distance [0, 765].
  float supportWeight(float l1) const;

  /// The window of pixel (px, py): sample positions, weights, colours, gradients and priors.
  void buildWindow(int px, int py, WindowCache& cache) const;

  /// C(p, plane) over the cached window. Stops early (returning a value >= bound) once the
  /// partial sum exceeds `bound`; exact otherwise. (Inline: called for every candidate plane.)
  float aggregate(const WindowCache& cache, const Plane& plane, float bound) const {
    if (avx512_) return aggregateAvx512(cache.kernel, kernel_, plane.a, plane.b, plane.c, bound);
    if (avx2_) return aggregateAvx2(cache.kernel, kernel_, plane.a, plane.b, plane.c, bound);
    return aggregateImpl(cache, plane, bound);
  }

  /// The costs of the planes d - h and d + h (plane.c -+ h) for the sub-pixel step, in one pass
  /// over the window: each sample's match is interpolated on the interval of its match under the
  /// plane itself (linear in the shift), so they are C exactly where the other view is linear
  /// between its pixels, and within h times a slope change of it elsewhere.
  void aggregateSides(const WindowCache& cache, const Plane& plane, float h, float& lower,
                      float& upper) const;

  /// phi's factors for a sample of support weight `w` whose prior has confidence `trust` (0: no
  /// prior), as the windows cache them (the SIMD window builders compute the same).
  PhiWeights phiWeights(float w, float trust) const;

  /// Whether this cost runs the AVX2 kernel.
  bool usesAvx2() const { return avx2_; }

  /// The window offsets used in x and y (windowOffsets of the parameters).
  const std::vector<int>& offsets() const { return offsets_; }

  /// The window's samples on the offsets' grid (windowRows of the parameters).
  const WindowRows& rows() const { return rows_; }

 private:
  // The constructor's steps: the table of w, the weights of phi, the window inside the image,
  // and the SIMD kernels' views of them (cost_kernel.h).
  void tabulateSupportWeight();
  void readCostWeights();
  void buildInteriorWindow();
  KernelSelf kernelSelf() const;
  KernelConstants kernelConstants() const;

  void buildWindowBaseline(int px, int py, WindowCache& cache) const;
  float aggregateImpl(const WindowCache& cache, const Plane& plane, float bound) const;
  void aggregateSidesImpl(const WindowCache& cache, const Plane& plane, float h, int shift_q,
                          float& lower, float& upper) const;

  static constexpr int kLutSize = 4096;
  static constexpr float kLutScale = 4.f;  ///< LUT entries per unit of RGB L1 distance

  const PatchMatchParams& p_;
  const ViewState& self_;
  const ViewState& other_;
  std::vector<int> offsets_;
  WindowRows rows_;
  std::vector<float> weight_lut_;
  /// KernelSelf's interior window: the samples' offsets (cost_kernel.h).
  std::vector<float> interior_dx_, interior_dy_;
  std::vector<int> interior_row_, interior_texel_, interior_pixel_;
  float wa_, wb_, wg_, lcol_, lgrad_, ldisp_, outside_cost_, img_norm_;
  bool use_grad_, use_prior_, weighted_;
  bool avx2_;    ///< AVX2 kernels (window, and the cost unless avx512_)
  bool avx512_;  ///< the AVX-512 cost
  KernelConstants kernel_;
  KernelSelf kernel_self_;
};

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
