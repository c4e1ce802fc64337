// PatchMatch: the aggregated cost C(p, xi), its weight w and per-sample cost phi (see cost.h).
#include "lidar_stereo_fusion/core/patchmatch/cost.h"

#include <algorithm>
#include <cmath>

#include "lidar_stereo_fusion/core/patchmatch/simd.h"

namespace lidar_stereo_fusion {
namespace patchmatch {

namespace {

/// The lanes' sum in the order of cost_kernel.h (the AVX2 kernel's).
float laneSum(const float* l) {
  return ((l[0] + l[4]) + (l[2] + l[6])) + ((l[1] + l[5]) + (l[3] + l[7]));
}

}  // namespace

std::vector<int> windowOffsets(int radius, int stride, bool dyadic) {
  std::vector<int> offsets;
  if (!dyadic) {
    for (int o = -radius; o <= radius; ++o) {
      if (o % stride == 0) offsets.push_back(o);
    }
    return offsets;
  }
  std::vector<int> positive;
  for (int o = stride; o <= radius; o *= 2) positive.push_back(o);
  for (auto it = positive.rbegin(); it != positive.rend(); ++it) offsets.push_back(-*it);
  offsets.push_back(0);
  offsets.insert(offsets.end(), positive.begin(), positive.end());
  return offsets;
}

void WindowCache::reserve(size_t n) {
  for (auto* v : {&xs, &ys, &w_img, &w_lidar, &c0, &c1, &c2, &g0, &g1, &priors}) v->assign(n, 0.f);
  row_offset.assign(n, 0);
  texels.assign(n, Texel{});
  texel_row.assign(n, 0);
}

MatchingCost::MatchingCost(const PatchMatchParams& params, const ViewState& self,
                           const ViewState& other)
    : p_(params), self_(self), other_(other) {
  offsets_ = windowOffsets(params.window_radius, params.window_stride, params.window_dyadic);
  weight_lut_.resize(kLutSize);
  for (int i = 0; i < kLutSize; ++i) {
    weight_lut_[i] = std::exp(-(i / kLutScale) / static_cast<float>(params.weight_delta));
  }
  wa_ = static_cast<float>(p_.alpha);
  wb_ = static_cast<float>(p_.beta);
  wg_ = static_cast<float>(p_.gamma);
  lcol_ = static_cast<float>(p_.lambda_col);
  lgrad_ = static_cast<float>(p_.lambda_grad);
  ldisp_ = static_cast<float>(p_.lambda_disp);
  outside_cost_ = wa_ * lcol_ + wb_ * lgrad_;
  use_grad_ = wb_ > 0.f;
  use_prior_ = wg_ > 0.f && !self_.prior.empty();
  weighted_ = p_.confidence_weighting;
  img_norm_ = wa_ + wb_ > 0.f ? 1.f / (wa_ + wb_) : 0.f;
  avx2_ = activeSimdPath() == SimdPath::kAvx2 && !self_.texels.empty() && !other_.texels.empty();
  const float x_max = static_cast<float>(self_.width - 1);
  kernel_self_ = KernelSelf{self_.texels.data()->v,
                            use_prior_ ? self_.prior.ptr<float>(0) : nullptr,
                            use_prior_ ? self_.trust.ptr<float>(0) : nullptr,
                            use_prior_ ? static_cast<int>(self_.prior.step1()) : 0,
                            use_prior_ ? static_cast<int>(self_.trust.step1()) : 0,
                            self_.width,
                            self_.height,
                            kTexelFloats * other_.width,
                            offsets_.data(),
                            static_cast<int>(offsets_.size()),
                            weight_lut_.data(),
                            kLutSize,
                            kLutScale,
                            weighted_,
                            wg_,
                            img_norm_,
                            ldisp_};
  kernel_ = KernelConstants{other_.texels.data()->v,
                            x_max,
                            x_max - 1e-3f,
                            self_.match_sign,
                            wa_,
                            use_grad_ ? wb_ : 0.f,
                            lcol_,
                            lgrad_,
                            ldisp_,
                            outside_cost_};
}

float MatchingCost::supportWeight(float l1) const {
  return weight_lut_[std::min(kLutSize - 1, static_cast<int>(l1 * kLutScale))];
}

void MatchingCost::buildWindow(int px, int py, WindowCache& cache) const {
  const size_t n = offsets_.size() * offsets_.size() + kSimdBlock;  // room for the padding
  if (cache.xs.size() < n) cache.reserve(n);
  if (avx2_) {
    const KernelWindowOut out{cache.xs.data(),       cache.ys.data(),     cache.w_img.data(),
                              cache.w_lidar.data(),  cache.priors.data(), cache.texels.data()->v,
                              cache.texel_row.data()};
    cache.count = buildWindowAvx2(kernel_self_, px, py, out, cache.padded, cache.constant);
    return;
  }
  cache.constant = 0.f;
  int k = 0;
  const cv::Vec3f center = self_.color(py, px);
  const int color_stride = 3 * other_.width;
  for (int dy : offsets_) {
    const int y = py + dy;
    if (y < 0 || y >= self_.height) continue;
    const cv::Vec3f* crow = self_.color.ptr<cv::Vec3f>(y);
    const cv::Vec2f* grow = use_grad_ ? self_.grad.ptr<cv::Vec2f>(y) : nullptr;
    const float* prow = use_prior_ ? self_.prior.ptr<float>(y) : nullptr;
    const float* trow = use_prior_ ? self_.trust.ptr<float>(y) : nullptr;
    for (int dx : offsets_) {
      const int x = px + dx;
      if (x < 0 || x >= self_.width) continue;
      const cv::Vec3f& c = crow[x];
      const float w = supportWeight(std::abs(c[0] - center[0]) + std::abs(c[1] - center[1]) +
                                    std::abs(c[2] - center[2]));
      cache.xs[k] = static_cast<float>(x);
      cache.ys[k] = static_cast<float>(y);
      cache.c0[k] = c[0];
      cache.c1[k] = c[1];
      cache.c2[k] = c[2];
      cache.row_offset[k] = y * color_stride;
      if (use_grad_) {
        cache.g0[k] = grow[x][0];
        cache.g1[k] = grow[x][1];
      }
      const float trust = use_prior_ ? trow[x] : 0.f;
      cache.priors[k] = use_prior_ ? prow[x] : 0.f;
      if (weighted_) {
        // phi = (1 - kappa) / (alpha + beta) rho_img + kappa rho_lid, kappa = gamma c(p').
        const float kappa = wg_ * trust;
        cache.w_img[k] = w * (1.f - kappa) * img_norm_;
        cache.w_lidar[k] = w * kappa;
      } else {
        // The paper: phi = rho_img + gamma rho_lid, or + gamma lambda_disp without a prior.
        cache.w_img[k] = w;
        cache.w_lidar[k] = trust > 0.f ? w * wg_ : 0.f;
        if (use_prior_ && !(trust > 0.f)) cache.constant += w * wg_ * ldisp_;
      }
      ++k;
    }
  }
  cache.count = k;
  cache.padded = k;
}

float MatchingCost::aggregate(const WindowCache& cache, const Plane& plane, float bound) const {
  if (avx2_) {
    const KernelWindow w{cache.xs.data(),        cache.ys.data(),     cache.w_img.data(),
                         cache.w_lidar.data(),   cache.priors.data(), cache.texels.data()->v,
                         cache.texel_row.data(), cache.padded,        cache.count,
                         cache.constant};
    return aggregateAvx2(w, kernel_, plane.a, plane.b, plane.c, bound);
  }
  return use_grad_ ? aggregateImpl<true>(cache, plane, bound)
                   : aggregateImpl<false>(cache, plane, bound);
}

void MatchingCost::aggregateSides(const WindowCache& cache, const Plane& plane, float h,
                                  float& lower, float& upper) const {
  if (avx2_) {
    const KernelWindow w{cache.xs.data(),        cache.ys.data(),     cache.w_img.data(),
                         cache.w_lidar.data(),   cache.priors.data(), cache.texels.data()->v,
                         cache.texel_row.data(), cache.padded,        cache.count,
                         cache.constant};
    aggregateSidesAvx2(w, kernel_, plane.a, plane.b, plane.c, h, lower, upper);
    return;
  }
  if (use_grad_) {
    aggregateSidesImpl<true>(cache, plane, h, lower, upper);
  } else {
    aggregateSidesImpl<false>(cache, plane, h, lower, upper);
  }
}

template <bool kGrad>
float MatchingCost::aggregateImpl(const WindowCache& cache, const Plane& plane, float bound) const {
  if (cache.constant >= bound) return cache.constant;
  const float x_max = static_cast<float>(self_.width - 1);
  const float x_clamp = x_max - 1e-3f;  // keeps i0 + 1 inside the row
  const float* other = other_.color.ptr<float>(0);
  const float* other_grad = kGrad ? other_.grad.ptr<float>(0) : nullptr;
  const float sign = self_.match_sign;
  const float a = plane.a, b = plane.b, c = plane.c;
  const float* xs = cache.xs.data();
  const float* ys = cache.ys.data();
  const float* wi = cache.w_img.data();
  const float* wl = cache.w_lidar.data();
  const float* c0 = cache.c0.data();
  const float* c1 = cache.c1.data();
  const float* c2 = cache.c2.data();
  const float* g0 = cache.g0.data();
  const float* g1 = cache.g1.data();
  const float* pr = cache.priors.data();
  const int* ro = cache.row_offset.data();
  // Terms are summed in kSimdBlock lanes (sample k into lane k % 8), the lanes reduced by
  // laneSum(), and the bound checked after every block of 8 samples: the AVX2 kernel's order, so
  // both return the same float. Most refinement candidates are worse than the current plane and
  // exceed it after a few blocks.
  float lanes[kSimdBlock] = {};
  for (int start = 0; start < cache.count; start += kSimdBlock) {
    const int end = std::min(cache.count, start + kSimdBlock);
    for (int k = start; k < end; ++k) {
      const float d = a * xs[k] + b * ys[k] + c;
      const float xm_raw = xs[k] + sign * d;
      const float inside = (xm_raw >= 0.f && xm_raw <= x_max) ? 1.f : 0.f;
      const float xm = std::min(std::max(xm_raw, 0.f), x_clamp);
      const int i0 = static_cast<int>(xm);
      const float f = xm - static_cast<float>(i0);
      const int idx = ro[k] + 3 * i0;
      // Colour of q by linear interpolation (sub-pixel match).
      const float m0 = other[idx] + f * (other[idx + 3] - other[idx]);
      const float m1 = other[idx + 1] + f * (other[idx + 4] - other[idx + 1]);
      const float m2 = other[idx + 2] + f * (other[idx + 5] - other[idx + 2]);
      const float col = std::abs(c0[k] - m0) + std::abs(c1[k] - m1) + std::abs(c2[k] - m2);
      float rho_img = wa_ * std::min(col, lcol_);
      if (kGrad) {
        const int gi = (ro[k] / 3) * 2 + 2 * i0;
        const float h0 = other_grad[gi] + f * (other_grad[gi + 2] - other_grad[gi]);
        const float h1 = other_grad[gi + 1] + f * (other_grad[gi + 3] - other_grad[gi + 1]);
        rho_img += wb_ * std::min(std::abs(g0[k] - h0) + std::abs(g1[k] - h1), lgrad_);
      }
      rho_img = inside * rho_img + (1.f - inside) * outside_cost_;
      const float rho_lid = std::min(std::abs(pr[k] - d), ldisp_);
      lanes[k - start] += wi[k] * rho_img + wl[k] * rho_lid;
    }
    const float sum = cache.constant + laneSum(lanes);
    if (sum >= bound) return sum;
  }
  return cache.constant + laneSum(lanes);
}

template <bool kGrad>
void MatchingCost::aggregateSidesImpl(const WindowCache& cache, const Plane& plane, float h,
                                      float& lower, float& upper) const {
  // aggregateImpl's operations in its order, with own - m moved by +- sign h (t1 - t0) (the
  // AVX2 kernel's, so both paths give the same floats).
  const float x_max = static_cast<float>(self_.width - 1);
  const float x_clamp = x_max - 1e-3f;
  const float* other = other_.color.ptr<float>(0);
  const float* other_grad = kGrad ? other_.grad.ptr<float>(0) : nullptr;
  const float sign = self_.match_sign, shift = self_.match_sign * h;
  float lanes_lower[kSimdBlock] = {}, lanes_upper[kSimdBlock] = {};
  for (int k = 0; k < cache.count; ++k) {
    const float d = plane.a * cache.xs[k] + plane.b * cache.ys[k] + plane.c;
    const float xm_raw = cache.xs[k] + sign * d;
    const bool inside = xm_raw >= 0.f && xm_raw <= x_max;
    const float xm = std::min(std::max(xm_raw, 0.f), x_clamp);
    const int i0 = static_cast<int>(xm);
    const float f = xm - static_cast<float>(i0);
    const int idx = cache.row_offset[k] + 3 * i0;
    const float own[3] = {cache.c0[k], cache.c1[k], cache.c2[k]};
    float col[2] = {}, grad[2] = {};  // lower, upper
    for (int side = 0; side < 2; ++side) {
      float l1[3];
      for (int ch = 0; ch < 3; ++ch) {
        const float slope = other[idx + 3 + ch] - other[idx + ch];
        const float diff = own[ch] - (other[idx + ch] + f * slope);
        l1[ch] = std::abs(side == 0 ? diff + shift * slope : diff - shift * slope);
      }
      col[side] = l1[0] + l1[1] + l1[2];
      if (kGrad) {
        const int gi = (cache.row_offset[k] / 3) * 2 + 2 * i0;
        const float own_g[2] = {cache.g0[k], cache.g1[k]};
        float g1[2];
        for (int ch = 0; ch < 2; ++ch) {
          const float slope = other_grad[gi + 2 + ch] - other_grad[gi + ch];
          const float diff = own_g[ch] - (other_grad[gi + ch] + f * slope);
          g1[ch] = std::abs(side == 0 ? diff + shift * slope : diff - shift * slope);
        }
        grad[side] = g1[0] + g1[1];
      }
    }
    const float dh[2] = {d - h, d + h};
    float* lanes[2] = {lanes_lower, lanes_upper};
    for (int side = 0; side < 2; ++side) {
      float rho_img = wa_ * std::min(col[side], lcol_);
      if (kGrad) rho_img += wb_ * std::min(grad[side], lgrad_);
      if (!inside) rho_img = outside_cost_;
      const float rho_lid = std::min(std::abs(cache.priors[k] - dh[side]), ldisp_);
      lanes[side][k % kSimdBlock] += cache.w_img[k] * rho_img + cache.w_lidar[k] * rho_lid;
    }
  }
  lower = cache.constant + laneSum(lanes_lower);
  upper = cache.constant + laneSum(lanes_upper);
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
