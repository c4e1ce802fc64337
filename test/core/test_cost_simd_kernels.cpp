// The AVX2 and AVX-512 matching-cost and weighted-median kernels against the baseline ones and a
// double-precision reference of the equations in patchmatch/cost.h, and the sub-pixel step's side
// costs. Which path runs, and whole PatchMatch runs on every path: test_cost_simd.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "cost_simd_util.h"
#include "lidar_stereo_fusion/core/patchmatch.h"
#include "lidar_stereo_fusion/core/patchmatch/cost.h"
#include "lidar_stereo_fusion/core/patchmatch/cost_kernel.h"
#include "lidar_stereo_fusion/core/patchmatch/median_kernel.h"
#include "lidar_stereo_fusion/core/patchmatch/simd.h"
#include "lidar_stereo_fusion/core/patchmatch/view_state.h"

namespace lsf = lidar_stereo_fusion;
namespace pm = lidar_stereo_fusion::patchmatch;

using lidar_stereo_fusion::test::widePaths;

namespace {

/// Random BGR noise image.
cv::Mat randomImage(int w, int h, std::mt19937& rng) {
  cv::Mat img(h, w, CV_8UC3);
  std::uniform_int_distribution<int> u(0, 255);
  for (auto it = img.begin<cv::Vec3b>(); it != img.end<cv::Vec3b>(); ++it) {
    *it = cv::Vec3b(u(rng), u(rng), u(rng));
  }
  return img;
}

/// A prior in [1, 60] px with ~30 % empty pixels, and a confidence with exact 0s and 1s.
void randomPrior(int w, int h, std::mt19937& rng, cv::Mat1f& prior, cv::Mat1f& confidence) {
  std::uniform_real_distribution<float> d(1.f, 60.f), u(0.f, 1.f);
  prior.create(h, w);
  confidence.create(h, w);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      prior(y, x) = u(rng) < 0.3f ? 0.f : d(rng);
      const float c = u(rng);
      confidence(y, x) = c < 0.2f ? 0.f : (c > 0.9f ? 1.f : c);
    }
  }
}

/// C(p, plane) of cost.h in double precision, straight from the equations, on the view's texels
/// (colour and gradient in the kernels' fixed point, the match interpolated as they do). w is the
/// implementation's: exp(-l / delta) with l the RGB L1 distance of the texels' colours (to 1/64
/// with image_smoothing) rounded down to 1/4 (its LUT).
/// Whether the window uses offset o: a multiple of the stride, and with dyadic sampling 0 or the
/// stride times a power of two.
bool usedOffset(const lsf::PatchMatchParams& p, int o) {
  const int m = std::abs(o);
  if (m % p.window_stride != 0) return false;
  const int k = m / p.window_stride;
  return !p.window_dyadic || k == 0 || (k & (k - 1)) == 0;
}

/// Whether the window uses the sample (dx, dy): both offsets used, and in a round window within
/// the radius of the centre.
bool usedSample(const lsf::PatchMatchParams& p, int dx, int dy) {
  if (!usedOffset(p, dx) || !usedOffset(p, dy)) return false;
  return !p.window_round || dx * dx + dy * dy <= p.window_radius * p.window_radius;
}

double referenceCost(const lsf::PatchMatchParams& p, const pm::ViewState& self,
                     const pm::ViewState& other, int px, int py, const pm::Plane& plane) {
  const bool use_prior = p.gamma > 0 && !self.prior.empty();
  const double alpha = p.alpha, beta = p.beta, gamma = p.gamma;
  // The colour a texel holds (cost_kernel.h), 0..255.
  const auto colour = [&](int x, int y, int i) {
    return double(self.texels[static_cast<size_t>(y) * self.width + x].v[i]) / pm::kTexelScale;
  };
  double sum = 0;
  for (int dy = -p.window_radius; dy <= p.window_radius; ++dy) {
    for (int dx = -p.window_radius; dx <= p.window_radius; ++dx) {
      const int x = px + dx, y = py + dy;
      if (!usedSample(p, dx, dy)) continue;
      if (x < 0 || y < 0 || x >= self.width || y >= self.height) continue;
      double l1 = 0;
      for (int i = 0; i < 3; ++i) l1 += std::abs(colour(x, y, i) - colour(px, py, i));
      const double w = std::exp(-std::min(std::floor(l1 * 4), 4095.0) / 4 / p.weight_delta);
      const double d = double(plane.a) * x + double(plane.b) * y + plane.c;
      const double xm = x + self.match_sign * d;
      double rho_img = alpha * p.lambda_col + beta * p.lambda_grad;  // match outside the image
      if (xm >= 0 && xm <= other.width - 1) {
        // The texels' fixed point (cost_kernel.h): the nodes to 1/kTexelScale, the fraction to
        // 2^-15, m rounded to 1/kTexelScale.
        const int x0 = std::min(static_cast<int>(xm), other.width - 2);
        const int fq =
            std::min(pm::kFracOne - 1, static_cast<int>(std::lround((xm - x0) * pm::kFracOne)));
        const short* t0 = other.texels[static_cast<size_t>(y) * other.width + x0].v;
        const short* t1 = t0 + pm::kTexelChannels;
        const short* own = self.texels[static_cast<size_t>(y) * self.width + x].v;
        double l1[pm::kTexelChannels];
        for (int i = 0; i < pm::kTexelChannels; ++i) {
          const double m = t0[i] + std::floor((t1[i] - t0[i]) * double(fq) / pm::kFracOne + 0.5);
          l1[i] = std::abs(own[i] - m) / pm::kTexelScale;
        }
        const double col = l1[0] + l1[1] + l1[2], grad = beta > 0 ? l1[4] + l1[5] : 0.0;
        rho_img = alpha * std::min(col, p.lambda_col) + beta * std::min(grad, p.lambda_grad);
      }
      const double prior = use_prior ? self.prior(y, x) : 0.0;
      const double trust = use_prior ? self.trust(y, x) : 0.0;
      const double rho_lid = std::min(std::abs(prior - d), p.lambda_disp);
      double phi;
      if (p.confidence_weighting) {
        const double kappa = gamma * trust;
        phi = (1 - kappa) / (alpha + beta) * rho_img + kappa * rho_lid;
      } else {
        phi = rho_img + (use_prior ? gamma * (trust > 0 ? rho_lid : p.lambda_disp) : 0.0);
      }
      sum += w * phi;
    }
  }
  return sum;
}

/// The AVX2 window (interior or at a border) holds the baseline's samples, bit for bit, and
/// zero weights on its padding.
void expectSameWindow(const pm::WindowCache& fast, const pm::WindowCache& base, int px, int py) {
  for (int k = 0; k < base.count; ++k) {
    const auto where = ::testing::Message() << "pixel " << px << "," << py << " sample " << k;
    ASSERT_EQ(fast.xs[k], base.xs[k]) << where;
    ASSERT_EQ(fast.ys[k], base.ys[k]) << where;
    ASSERT_EQ(fast.texel_row[k], base.texel_row[k]) << where;
    ASSERT_EQ(fast.priors[k], base.priors[k]) << where;
    ASSERT_EQ(fast.w_img[k], base.w_img[k]) << where;
    ASSERT_EQ(fast.w_lidar[k], base.w_lidar[k]) << where;
    for (int c = 0; c < pm::kTexelChannels; ++c) {
      ASSERT_EQ(fast.texels[k].v[c], base.texels[k].v[c]) << where << " channel " << c;
    }
  }
  for (int k = base.count; k < fast.padded; ++k) {
    ASSERT_EQ(fast.w_img[k], 0.f) << "padding " << k;
    ASSERT_EQ(fast.w_lidar[k], 0.f) << "padding " << k;
  }
  ASSERT_EQ(fast.constant, base.constant);
}

struct CostCase {
  bool weighted, with_prior, with_grad;
};

/// Both kernels and the reference on random windows (borders included) and random planes, some
/// matching outside the other image; then with random bounds (early exit). Square or round.
void compareShape(const CostCase& cc, uint32_t seed, lsf::SimdPath wide, int radius, int stride,
                  bool round) {
  std::mt19937 rng(seed);
  const int w = 97, h = 41;
  lsf::PatchMatchParams p;
  p.window_radius = radius;
  p.window_stride = stride;
  p.confidence_weighting = cc.weighted;
  p.window_dyadic = seed % 2 == 0;  // both window patterns
  p.window_round = round;
  if (!cc.with_grad) {
    p.alpha = 0.1;
    p.beta = 0.0;
  }
  cv::Mat1f prior, confidence;
  if (cc.with_prior) randomPrior(w, h, rng, prior, confidence);
  const lsf::ViewInput left(randomImage(w, h, rng), prior, {}, confidence);
  const lsf::ViewInput right(randomImage(w, h, rng), prior, {}, confidence);
  pm::ViewState lv, rv;
  pm::prepareView(left, p, -1.f, lv);
  pm::prepareView(right, p, +1.f, rv);
  for (const pm::ViewState* self : {&lv, &rv}) {
    const pm::ViewState& other = self == &lv ? rv : lv;
    // Both costs at once in one process, each with its own path.
    lsf::PatchMatchParams fast_params = p, base_params = p;
    fast_params.simd_path = wide;
    base_params.simd_path = lsf::SimdPath::kBaseline;
    const pm::MatchingCost fast(fast_params, *self, other);
    const pm::MatchingCost base(base_params, *self, other);
    ASSERT_TRUE(fast.usesAvx2());
    ASSERT_FALSE(base.usesAvx2());
    pm::WindowCache fast_cache, base_cache;
    std::uniform_int_distribution<int> ux(0, w - 1), uy(0, h - 1);
    std::uniform_real_distribution<float> slope(-0.6f, 0.6f), disp(-30.f, 90.f), u01(0.f, 1.f);
    for (int i = 0; i < 400; ++i) {
      const int px = ux(rng), py = uy(rng);
      const float a = slope(rng), b = slope(rng);
      const pm::Plane plane{a, b, disp(rng) - a * px - b * py};
      fast.buildWindow(px, py, fast_cache);
      base.buildWindow(px, py, base_cache);
      ASSERT_EQ(fast_cache.count, base_cache.count);
      ASSERT_EQ(fast_cache.padded % pm::kSimdBlock, 0);
      expectSameWindow(fast_cache, base_cache, px, py);
      const float inf = std::numeric_limits<float>::max();
      const float cf = fast.aggregate(fast_cache, plane, inf);
      const float cb = base.aggregate(base_cache, plane, inf);
      const double ref = referenceCost(p, *self, other, px, py, plane);
      const auto where = ::testing::Message()
                         << (wide == lsf::SimdPath::kAvx512 ? "avx512" : "avx2") << " seed " << seed
                         << (round ? " round" : " square") << " pixel " << px << "," << py
                         << " plane " << a << " " << b << " " << plane.c;
      // The wide kernels repeat the baseline's float operations in its order: bit-identical.
      ASSERT_EQ(cf, cb) << where;
      ASSERT_NEAR(cb, ref, 1e-4 * std::max(1e-3, ref)) << where;
      ASSERT_NEAR(cf, ref, 1e-4 * std::max(1e-3, ref)) << where;
      // The sub-pixel step's costs at d -+ h, in one pass: bit-identical too.
      float fast_lower, fast_upper, base_lower, base_upper;
      fast.aggregateSides(fast_cache, plane, 0.1f, fast_lower, fast_upper);
      base.aggregateSides(base_cache, plane, 0.1f, base_lower, base_upper);
      ASSERT_EQ(fast_lower, base_lower) << where;
      ASSERT_EQ(fast_upper, base_upper) << where;
      // Early exit: a result below the bound is the full sum; else the full sum is not below it.
      const float bound = cb * 2.f * u01(rng);
      const float rf = fast.aggregate(fast_cache, plane, bound);
      const float rb = base.aggregate(base_cache, plane, bound);
      ASSERT_EQ(rf, rb) << where << " bound " << bound;  // same exit point too
      for (const float r : {rf, rb}) {
        if (r < bound) {
          ASSERT_NEAR(r, cb, 1e-5 * std::max(1e-3f, cb)) << where << " bound " << bound;
        } else {
          ASSERT_GE(cb, bound * (1 - 1e-5f)) << where << " bound " << bound;
        }
      }
    }
  }
}

/// compareShape on the square and on the round window.
void compareKernels(const CostCase& cc, uint32_t seed, lsf::SimdPath wide, int radius = 8,
                    int stride = 2) {
  for (const bool round : {false, true}) compareShape(cc, seed, wide, radius, stride, round);
}

}  // namespace

TEST(CostSimd, KernelsAgreeConfidenceWeighted) {
  SKIP_WITHOUT_AVX2();
  for (const lsf::SimdPath wide : widePaths()) compareKernels({true, true, true}, 1, wide);
}

TEST(CostSimd, KernelsAgreePaperCost) {
  SKIP_WITHOUT_AVX2();
  for (const lsf::SimdPath wide : widePaths()) compareKernels({false, true, true}, 2, wide);
}

TEST(CostSimd, KernelsAgreeWithoutPrior) {
  SKIP_WITHOUT_AVX2();
  for (const lsf::SimdPath wide : widePaths()) {
    compareKernels({true, false, true}, 3, wide);
    compareKernels({false, false, true}, 4, wide);
  }
}

TEST(CostSimd, KernelsAgreeWithoutGradient) {
  SKIP_WITHOUT_AVX2();
  for (const lsf::SimdPath wide : widePaths()) {
    compareKernels({true, true, false}, 5, wide);
    compareKernels({false, true, false}, 6, wide);
  }
}

TEST(CostSimd, Avx512KernelsAgree) {
  if (!lsf::cpuHasAvx512()) {
    GTEST_SKIP() << "this CPU (or build) has no AVX-512: the AVX2 and baseline paths are tested";
  }
  // Windows the kernel steps through differently: 7 x 7 and 9 x 9 samples (16 at a time and a
  // last 8; the other tests), 5 x 5 (16 and 16), 3 x 3 (one step of 16, 9 of them real), 11 x 11
  // (the paper's; an odd seed is not dyadic), and border windows of each; round, the 7 x 7's 29
  // samples (16 and 16), the 5 x 5's 13 (the coarsest level's: one step), the 3 x 3's 5 and the
  // 11 x 11's 81.
  compareKernels({true, true, true}, 7, lsf::SimdPath::kAvx512, 2, 1);
  compareKernels({false, true, true}, 8, lsf::SimdPath::kAvx512, 2, 1);
  compareKernels({true, true, true}, 9, lsf::SimdPath::kAvx512, 2, 2);
  compareKernels({true, true, false}, 13, lsf::SimdPath::kAvx512, 5, 1);  // odd: not dyadic
}

TEST(CostSimd, WeightedMedianKernelsAgree) {
  SKIP_WITHOUT_AVX2();
  // Random windows of every size the fill sees (up to 6 x 6 samples, and beyond), with ties and
  // zero weights: both kernels give the reference's float, the smallest d whose weight summed in
  // window order over the d's not above it reaches half the total.
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> ud(0.5f, 40.f), uw(0.f, 1.f);
  for (int n = 1; n <= 70; ++n) {
    for (int rep = 0; rep < 20; ++rep) {
      const int padded = (n + pm::kMedianLanes - 1) / pm::kMedianLanes * pm::kMedianLanes;
      std::vector<float> d(padded, std::numeric_limits<float>::max()), w(padded, 0.f);
      float total = 0.f;
      for (int i = 0; i < n; ++i) {
        d[i] = rep % 3 == 0 ? std::round(ud(rng)) : ud(rng);  // ties every third window
        w[i] = rep % 4 == 0 && i % 3 == 0 ? 0.f : uw(rng);
        total += w[i];
      }
      const float half = 0.5f * total;
      float expected = std::numeric_limits<float>::max();
      for (int i = 0; i < n; ++i) {
        float cumulative = 0.f;
        for (int j = 0; j < n; ++j) cumulative += d[j] <= d[i] ? w[j] : 0.f;
        if (cumulative >= half) expected = std::min(expected, d[i]);
      }
      const auto where = ::testing::Message() << "n " << n << " window " << rep;
      ASSERT_EQ(pm::weightedMedianAvx2(d.data(), w.data(), n, padded, half), expected) << where;
      if (lsf::cpuHasAvx512()) {
        ASSERT_EQ(pm::weightedMedianAvx512(d.data(), w.data(), n, padded, half), expected) << where;
      }
    }
  }
}

TEST(CostSimd, SidesAreTheShiftedPlanesCostsWhereTheOtherViewIsLinear) {
  // The right view is a ramp in x (linear colour, constant gradient inside), so interpolating on
  // the interval of d's match is exact for d -+ h too.
  std::mt19937 rng(12);
  const int w = 97, h = 41;
  cv::Mat ramp(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) ramp.at<cv::Vec3b>(y, x) = cv::Vec3b(2 * x, 255 - 2 * x, x);
  }
  cv::Mat1f prior, confidence;
  randomPrior(w, h, rng, prior, confidence);
  const lsf::ViewInput left(randomImage(w, h, rng), prior, {}, confidence);
  const lsf::ViewInput right(ramp, prior, {}, confidence);
  std::vector<lsf::SimdPath> paths = widePaths();
  paths.insert(paths.begin(), lsf::SimdPath::kBaseline);
  for (const lsf::SimdPath path : paths) {
    lsf::PatchMatchParams p;
    p.simd_path = path;
    pm::ViewState lv, rv;
    pm::prepareView(left, p, -1.f, lv);
    pm::prepareView(right, p, +1.f, rv);
    const pm::MatchingCost cost(p, lv, rv);
    pm::WindowCache cache;
    std::uniform_int_distribution<int> ux(24, 72), uy(0, h - 1);
    std::uniform_real_distribution<float> slope(-0.05f, 0.05f), disp(2.f, 10.f);
    const float step = 0.1f, inf = std::numeric_limits<float>::max();
    for (int i = 0; i < 200; ++i) {
      const int px = ux(rng), py = uy(rng);
      const float a = slope(rng), b = slope(rng);
      const pm::Plane plane{a, b, disp(rng) - a * px - b * py};
      cost.buildWindow(px, py, cache);
      float lower, upper;
      cost.aggregateSides(cache, plane, step, lower, upper);
      const float exact_lower = cost.aggregate(cache, {a, b, plane.c - step}, inf);
      const float exact_upper = cost.aggregate(cache, {a, b, plane.c + step}, inf);
      const auto where = ::testing::Message()
                         << lsf::simdPathName(path) << " pixel " << px << "," << py;
      EXPECT_NEAR(lower, exact_lower, 1e-4 * exact_lower) << where;
      EXPECT_NEAR(upper, exact_upper, 1e-4 * exact_upper) << where;
    }
  }
}
