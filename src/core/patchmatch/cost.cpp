// PatchMatch: the aggregated cost C(p, xi), its weight w and per-sample cost phi (see cost.h).
#include "lidar_stereo_fusion/core/patchmatch/cost.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

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

WindowRows windowRows(const std::vector<int>& offsets, int radius, bool round) {
  WindowRows rows;
  const int m = static_cast<int>(offsets.size());
  for (int dy : offsets) {
    int first = 0, end = m;
    if (round) {
      const auto inside = [&](int dx) { return dx * dx + dy * dy <= radius * radius; };
      while (first < end && !inside(offsets[first])) ++first;
      while (end > first && !inside(offsets[end - 1])) --end;
    }
    rows.first.push_back(first);
    rows.end.push_back(end);
    rows.count += end - first;
  }
  return rows;
}

void WindowCache::reserve(size_t n) {
  for (auto* v : {&xs, &ys, &w_img, &w_lidar, &priors}) v->assign(n, 0.f);
  texels.assign(n, Texel{});
  texel_row.assign(n, 0);
}

MatchingCost::MatchingCost(const PatchMatchParams& params, const ViewState& self,
                           const ViewState& other)
    : p_(params), self_(self), other_(other) {
  offsets_ = windowOffsets(params.window_radius, params.window_stride, params.window_dyadic);
  rows_ = windowRows(offsets_, params.window_radius, params.window_round);
  if (offsets_.size() > static_cast<size_t>(kMaxWindowOffsets)) {  // validate() keeps it out
    throw std::invalid_argument("MatchingCost: window_radius beyond PatchMatchParams's limit");
  }
  tabulateSupportWeight();
  readCostWeights();
  avx2_ = params.simd_path != SimdPath::kBaseline;
  avx512_ = params.simd_path == SimdPath::kAvx512;
  buildInteriorWindow();
  kernel_self_ = kernelSelf();
  kernel_ = kernelConstants();
}

void MatchingCost::tabulateSupportWeight() {
  weight_lut_.resize(kLutSize);
  for (int i = 0; i < kLutSize; ++i) {
    weight_lut_[i] = std::exp(-(i / kLutScale) / static_cast<float>(p_.weight_delta));
  }
}

void MatchingCost::readCostWeights() {
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
}

void MatchingCost::buildInteriorWindow() {
  // A window wholly inside the image has the same samples at the same offsets for every pixel;
  // the padding repeats the first sample.
  const int other_stride = kTexelChannels * other_.width;
  const auto add_interior = [&](int dx, int dy) {
    interior_dx_.push_back(static_cast<float>(dx));
    interior_dy_.push_back(static_cast<float>(dy));
    interior_row_.push_back(dy * other_stride);
    interior_texel_.push_back((dy * self_.width + dx) * kTexelChannels);
    interior_pixel_.push_back(dy * self_.width + dx);
  };
  for (size_t i = 0; i < offsets_.size(); ++i) {
    for (int j = rows_.first[i]; j < rows_.end[i]; ++j) add_interior(offsets_[j], offsets_[i]);
  }
  while (interior_dx_.size() % kSimdBlock != 0) {
    add_interior(static_cast<int>(interior_dx_[0]), static_cast<int>(interior_dy_[0]));
  }
}

KernelSelf MatchingCost::kernelSelf() const {
  const bool pixel_steps = !use_prior_ || (static_cast<int>(self_.prior.step1()) == self_.width &&
                                           static_cast<int>(self_.trust.step1()) == self_.width);
  return KernelSelf{self_.texels.empty() ? nullptr : self_.texels.data()->v,
                    use_prior_ ? self_.prior.ptr<float>(0) : nullptr,
                    use_prior_ ? self_.trust.ptr<float>(0) : nullptr,
                    use_prior_ ? static_cast<int>(self_.prior.step1()) : 0,
                    use_prior_ ? static_cast<int>(self_.trust.step1()) : 0,
                    self_.width,
                    self_.height,
                    kTexelChannels * other_.width,
                    offsets_.data(),
                    static_cast<int>(offsets_.size()),
                    rows_.first.data(),
                    rows_.end.data(),
                    rows_.count,
                    weight_lut_.data(),
                    kLutSize,
                    kLutScale,
                    weighted_,
                    wg_,
                    img_norm_,
                    ldisp_,
                    interior_dx_.data(),
                    interior_dy_.data(),
                    interior_row_.data(),
                    interior_texel_.data(),
                    pixel_steps ? interior_pixel_.data() : nullptr};
}

KernelConstants MatchingCost::kernelConstants() const {
  // The L1 sums are in texel units: alpha min(L1 / 64, lambda) = alpha / 64 min(L1, 64 lambda),
  // exactly (powers of two).
  const float scale = static_cast<float>(kTexelScale);
  const float x_max = static_cast<float>(self_.width - 1);
  return KernelConstants{other_.texels.empty() ? nullptr : other_.texels.data()->v,
                         x_max,
                         x_max - 1e-3f,
                         self_.match_sign,
                         wa_ / scale,
                         use_grad_ ? wb_ / scale : 0.f,
                         lcol_ * scale,
                         lgrad_ * scale,
                         ldisp_,
                         outside_cost_};
}

PhiWeights MatchingCost::phiWeights(float w, float trust) const {
  if (weighted_) {
    // phi = (1 - kappa) / (alpha + beta) rho_img + kappa rho_lid, kappa = gamma c(p').
    const float kappa = wg_ * trust;
    return PhiWeights{w * (1.f - kappa) * img_norm_, w * kappa, 0.f};
  }
  // The paper: phi = rho_img + gamma rho_lid, or + gamma lambda_disp without a prior.
  const bool measured = trust > 0.f;
  return PhiWeights{w, measured ? w * wg_ : 0.f, use_prior_ && !measured ? w * wg_ * ldisp_ : 0.f};
}

float MatchingCost::supportWeight(float l1) const {
  return weight_lut_[std::min(kLutSize - 1, static_cast<int>(l1 * kLutScale))];
}

void MatchingCost::buildWindow(int px, int py, WindowCache& cache) const {
  const size_t n = rows_.count + kSimdBlock;  // room for the padding
  if (cache.xs.size() < n) cache.reserve(n);
  if (!avx2_) {
    buildWindowBaseline(px, py, cache);
    return;
  }
  const KernelWindowOut out{cache.xs.data(),       cache.ys.data(),     cache.w_img.data(),
                            cache.w_lidar.data(),  cache.priors.data(), cache.texels.data()->v,
                            cache.texel_row.data()};
  cache.count = buildWindowAvx2(kernel_self_, px, py, out, cache.padded, cache.constant);
  cache.kernel = KernelWindow{cache.xs.data(),        cache.ys.data(),     cache.w_img.data(),
                              cache.w_lidar.data(),   cache.priors.data(), cache.texels.data()->v,
                              cache.texel_row.data(), cache.padded,        cache.count,
                              cache.constant};
}

void MatchingCost::buildWindowBaseline(int px, int py, WindowCache& cache) const {
  cache.constant = 0.f;
  int k = 0;
  const short* center =
      self_.texels.data()->v + (static_cast<long>(py) * self_.width + px) * kTexelChannels;
  const float texel_unit = 1.f / static_cast<float>(kTexelScale);  // exact: a power of two
  for (size_t i = 0; i < offsets_.size(); ++i) {
    const int y = py + offsets_[i];
    if (y < 0 || y >= self_.height) continue;
    const float* prow = use_prior_ ? self_.prior.ptr<float>(y) : nullptr;
    const float* trow = use_prior_ ? self_.trust.ptr<float>(y) : nullptr;
    for (int j = rows_.first[i]; j < rows_.end[i]; ++j) {
      const int x = px + offsets_[j];
      if (x < 0 || x >= self_.width) continue;
      const Texel& t = self_.texels[static_cast<size_t>(y) * self_.width + x];
      const int l1 = std::abs(t.v[0] - center[0]) + std::abs(t.v[1] - center[1]) +
                     std::abs(t.v[2] - center[2]);
      const float w = supportWeight(static_cast<float>(l1) * texel_unit);
      cache.xs[k] = static_cast<float>(x);
      cache.ys[k] = static_cast<float>(y);
      cache.texels[k] = t;
      cache.texel_row[k] = y * kTexelChannels * other_.width;
      cache.priors[k] = use_prior_ ? prow[x] : 0.f;
      const PhiWeights phi = phiWeights(w, use_prior_ ? trow[x] : 0.f);
      cache.w_img[k] = phi.image;
      cache.w_lidar[k] = phi.lidar;
      cache.constant += phi.constant;
      ++k;
    }
  }
  cache.count = k;
  cache.padded = k;
}

void MatchingCost::aggregateSides(const WindowCache& cache, const Plane& plane, float h,
                                  float& lower, float& upper) const {
  // The match's move by sign h in the fixed point of the interpolation fraction.
  const int shift_q = static_cast<int>(std::lround(self_.match_sign * h * kFracOne));
  if (avx512_) {
    aggregateSidesAvx512(cache.kernel, kernel_, plane.a, plane.b, plane.c, h, shift_q, lower,
                         upper);
    return;
  }
  if (avx2_) {
    aggregateSidesAvx2(cache.kernel, kernel_, plane.a, plane.b, plane.c, h, shift_q, lower, upper);
    return;
  }
  aggregateSidesImpl(cache, plane, h, shift_q, lower, upper);
}

namespace {

/// _mm256_mulhrs_epi16 of one lane: round(a b / 2^15).
inline int mulhrs(int a, int b) { return (a * b + (1 << 14)) >> 15; }

/// The texel channels that carry a value: B, G, R, gx, gy.
constexpr int kUsedChannels[] = {0, 1, 2, 4, 5};

/// The image term of one sample from its per-channel |own - m| in texel units (cost_kernel.h's
/// constants), or the outside cost where the match left the image: the AVX2 kernels' imageTerm.
inline float imageTerm(const KernelConstants& kc, const int* l1, bool inside) {
  if (!inside) return kc.outside_cost;
  const float col = static_cast<float>((l1[0] + l1[1]) + l1[2]);
  const float grad = static_cast<float>(l1[4] + l1[5]);
  return kc.alpha * std::min(col, kc.lambda_col) + kc.beta * std::min(grad, kc.lambda_grad);
}

/// Where sample k's plane disparity d matches in the other view, as both kernels compute it:
/// `inside` the image, the left node's offset in the other view's texels [shorts] and the
/// fraction in fixed point.
/// The LiDAR term rho_lid = min(|Pi(p') - d|, lambda_disp) of a sample with prior Pi(p').
inline float lidarTerm(float prior, float d, float lambda_disp) {
  return std::min(std::abs(prior - d), lambda_disp);
}

/// w(p, p') phi(p', q) of window sample k from its image and LiDAR terms, with the factors of
/// MatchingCost::phiWeights that buildWindow cached (the plane-independent part is in `constant`).
inline float weightedPhi(const WindowCache& cache, int k, float rho_img, float rho_lid) {
  return cache.w_img[k] * rho_img + cache.w_lidar[k] * rho_lid;
}

struct Match {
  bool inside;
  int node;
  int frac_q;
};

inline Match matchOf(float x, float d, float sign, float x_max, float x_clamp, int row) {
  const float xm_raw = x + sign * d;
  const float xm = std::min(std::max(xm_raw, 0.f), x_clamp);  // keeps i0 + 1 inside the row
  const int i0 = static_cast<int>(xm);
  // round(f 2^15) to nearest even (the kernel's conversion), at most 2^15 - 1 (its saturation).
  const float f = xm - static_cast<float>(i0);
  const int frac_q = std::min(kFracOne - 1, static_cast<int>(std::nearbyint(f * kFracOne)));
  return Match{xm_raw >= 0.f && xm_raw <= x_max, row + i0 * kTexelChannels, frac_q};
}

}  // namespace

float MatchingCost::aggregateImpl(const WindowCache& cache, const Plane& plane, float bound) const {
  if (cache.constant >= bound) return cache.constant;
  const float x_max = static_cast<float>(self_.width - 1);
  const short* other = other_.texels.data()->v;
  const KernelConstants& kc = kernel_;
  // Terms are summed in kSimdBlock lanes (sample k into lane k % 8), the lanes reduced by
  // laneSum(), and the bound checked after every second block of 8 samples: the AVX2 kernel's
  // order, so both return the same float. Most refinement candidates are worse than the current
  // plane and exceed it after a few blocks.
  float lanes[kSimdBlock] = {};
  for (int start = 0; start < cache.count; start += kSimdBlock) {
    const int end = std::min(cache.count, start + kSimdBlock);
    for (int k = start; k < end; ++k) {
      const float d = plane.a * cache.xs[k] + plane.b * cache.ys[k] + plane.c;
      const Match m = matchOf(cache.xs[k], d, kc.sign, x_max, kc.x_clamp, cache.texel_row[k]);
      // The match's texel by linear interpolation (sub-pixel match), in fixed point.
      const short* t0 = other + m.node;
      const short* own = cache.texels[k].v;
      int l1[kTexelChannels] = {};  // channels 3, 6 and 7 are 0 in every texel
      for (const int c : kUsedChannels) {
        l1[c] = std::abs(own[c] - (t0[c] + mulhrs(t0[kTexelChannels + c] - t0[c], m.frac_q)));
      }
      const float rho_img = imageTerm(kc, l1, m.inside);
      const float rho_lid = lidarTerm(cache.priors[k], d, kc.lambda_disp);
      lanes[k - start] += weightedPhi(cache, k, rho_img, rho_lid);
    }
    if ((start / kSimdBlock) % 2 == 1) {
      const float sum = cache.constant + laneSum(lanes);
      if (sum >= bound) return sum;
    }
  }
  return cache.constant + laneSum(lanes);
}

void MatchingCost::aggregateSidesImpl(const WindowCache& cache, const Plane& plane, float h,
                                      int shift_q, float& lower, float& upper) const {
  // aggregateImpl's operations in its order, with own - m moved by -+ the interpolation step's
  // share of the shift (the AVX2 kernel's, so both paths give the same floats).
  const float x_max = static_cast<float>(self_.width - 1);
  const short* other = other_.texels.data()->v;
  const KernelConstants& kc = kernel_;
  float lanes_lower[kSimdBlock] = {}, lanes_upper[kSimdBlock] = {};
  for (int k = 0; k < cache.count; ++k) {
    const float d = plane.a * cache.xs[k] + plane.b * cache.ys[k] + plane.c;
    const Match m = matchOf(cache.xs[k], d, kc.sign, x_max, kc.x_clamp, cache.texel_row[k]);
    const short* t0 = other + m.node;
    const short* own = cache.texels[k].v;
    int l1_lower[kTexelChannels] = {}, l1_upper[kTexelChannels] = {};
    for (const int c : kUsedChannels) {
      const int slope = t0[kTexelChannels + c] - t0[c];
      const int diff = own[c] - (t0[c] + mulhrs(slope, m.frac_q));
      const int moved = mulhrs(slope, shift_q);
      l1_lower[c] = std::abs(diff + moved);
      l1_upper[c] = std::abs(diff - moved);
    }
    const int* l1s[2] = {l1_lower, l1_upper};
    const float dh[2] = {d - h, d + h};
    float* lanes[2] = {lanes_lower, lanes_upper};
    for (int side = 0; side < 2; ++side) {
      const float rho_img = imageTerm(kc, l1s[side], m.inside);
      const float rho_lid = lidarTerm(cache.priors[k], dh[side], kc.lambda_disp);
      lanes[side][k % kSimdBlock] += weightedPhi(cache, k, rho_img, rho_lid);
    }
  }
  lower = cache.constant + laneSum(lanes_lower);
  upper = cache.constant + laneSum(lanes_upper);
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
