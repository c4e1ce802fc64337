// LiDAR-guided PatchMatch stereo (Bleyer et al. 2011 + the LiDAR term of Xu et al.).
//
// Readings of the paper taken here (METHOD.md section 3):
//  * Colour and gradient distances are L1 sums over channels (RGB on the 0..255 scale; gradient =
//    central differences of the grey image in x and y), as in Bleyer et al.
//  * Where the up-sampled prior is empty, the disparity term is the truncation lambda_disp: a
//    constant per window sample, so it never rewards a plane (it is added once per pixel).
//  * A sample whose match falls outside the other image costs the colour/gradient truncations.
//  * Search bounds: a plane is accepted for pixel p only if its disparity at p lies in
//    [lo(p), hi(p)] from the scan lines above and below (plus a margin), and always in
//    [min_disparity, max_disparity]. Refinement starts from Delta_d_max = max(|d_up - d_down|,
//    min_refine_range) between scan lines (else half the image's disparity range).
//  * Parallelism: the image is cut into horizontal strips processed in two phases (even strips in
//    parallel, then odd strips), each strip swept sequentially in the paper's order. Adjacent
//    strips are never written at the same time, so the sweep is race-free; random numbers come
//    from a counter-based generator keyed by (seed, view, iteration, pixel), so the result does
//    not depend on the number of threads.
//  * The image's [d_min, d_max] (used where fewer than two scan lines bound a pixel) is the range
//    of this frame's prior disparities (+ bound_margin) when LiDAR bounds are on.
//  * Per iteration: left view sweep (spatial propagation + refinement). In the last
//    `right_iterations` iterations also: view propagation of the left planes into the right view,
//    right view sweep, view propagation back into the left.
//  * Post-processing: left-right check (pixels whose match leaves the image are kept), the prior
//    fills inconsistent pixels where it has a value; elsewhere the lower (background) disparity of
//    the nearest consistent planes left and right, then a colour-weighted median over those.
#include "lidar_stereo_fusion/core/patchmatch.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace lidar_stereo_fusion {

namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("PatchMatchParams: " + message);
}

/// Plane d = a x + b y + c in the pixel coordinates of its view.
struct Plane {
  float a = 0.f, b = 0.f, c = 0.f;
  float at(float x, float y) const { return a * x + b * y + c; }
};

/// Plane from the disparity d at (x, y) and a unit normal n (nz != 0).
Plane planeFromNormal(float x, float y, float d, float nx, float ny, float nz) {
  Plane p;
  p.a = -nx / nz;
  p.b = -ny / nz;
  p.c = (nx * x + ny * y + nz * d) / nz;
  return p;
}

/// Unit normal of a plane (nz > 0).
void normalOf(const Plane& p, float& nx, float& ny, float& nz) {
  const float inv = 1.f / std::sqrt(p.a * p.a + p.b * p.b + 1.f);
  nx = -p.a * inv;
  ny = -p.b * inv;
  nz = inv;
}

/// Transfers a plane between views. A left point (x, y, d) is the right point (x - d, y, d):
/// d = a (x_r + d) + b y + c  =>  d = (a x_r + b y + c) / (1 - a). The inverse uses -a.
Plane transferPlane(const Plane& p, bool left_to_right) {
  const float k = left_to_right ? 1.f / (1.f - p.a) : 1.f / (1.f + p.a);
  return Plane{p.a * k, p.b * k, p.c * k};
}

/// Counter-based random numbers (splitmix64): deterministic per (seed, stream).
struct Rng {
  uint64_t state;
  explicit Rng(uint64_t seed) : state(seed) {}
  uint64_t next() {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// Uniform in [lo, hi).
  float uniform(float lo, float hi) {
    return lo + (hi - lo) * static_cast<float>((next() >> 40) * (1.0 / 16777216.0));
  }
};

uint64_t streamKey(uint64_t seed, int view, int iteration, int pixel) {
  Rng r(seed ^ (static_cast<uint64_t>(view + 1) << 56) ^
        (static_cast<uint64_t>(iteration + 1) << 40) ^ static_cast<uint64_t>(pixel));
  return r.next();
}

/// Everything PatchMatch keeps about one view.
struct ViewState {
  int width = 0, height = 0;
  float match_sign = -1.f;  ///< the match of x is at x + sign * d in the other view
  cv::Mat3f color;          ///< BGR float
  cv::Mat2f grad;           ///< (gx, gy) of the grey image; empty when beta == 0
  cv::Mat1f prior;          ///< 0 = empty
  cv::Mat1f lo, hi, range;  ///< search bounds (empty: unbounded)
  float d_min = 0.f, d_max = 0.f;  ///< the image's disparity range (see imageRange)
  std::vector<Plane> planes;
  std::vector<float> cost;

  bool bounded(int x, int y) const { return !lo.empty() && hi(y, x) > 0.f; }
};

/// The window samples of one pixel in structure-of-arrays form: positions, weights and the
/// values of this view, built once per pixel and shared by all candidate planes. The arrays are
/// sized once; `count` says how many entries are in use.
struct WindowCache {
  std::vector<float> xs, ys, weights, c0, c1, c2, g0, g1, priors, prior_valid;
  std::vector<int> row_offset;  ///< start of the sample's row in the other view's data [floats]
  float constant = 0.f;         ///< sum of the constant terms (empty-prior disparity term)
  int count = 0;

  void reserve(size_t n) {
    for (auto* v : {&xs, &ys, &weights, &c0, &c1, &c2, &g0, &g1, &priors, &prior_valid}) {
      v->assign(n, 0.f);
    }
    row_offset.assign(n, 0);
  }
};

constexpr float kSamePlaneTolerance = 0.01f;  // [px]

/// True when two planes agree to kSamePlaneTolerance px at (x, y) and to 1e-3 in slope:
/// evaluating one after the other cannot change the result meaningfully.
bool nearlySame(const Plane& p, const Plane& q, float x, float y) {
  return std::abs(p.at(x, y) - q.at(x, y)) < kSamePlaneTolerance && std::abs(p.a - q.a) < 1e-3f &&
         std::abs(p.b - q.b) < 1e-3f;
}

class Solver {
 public:
  Solver(const PatchMatchParams& params, ViewState& self, const ViewState& other)
      : p_(params), self_(self), other_(other) {
    for (int o = -params.window_radius; o <= params.window_radius; ++o) {
      if (o % params.window_stride == 0) offsets_.push_back(o);
    }
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
  }

  void buildCache(int px, int py, WindowCache& cache) const {
    const size_t n = offsets_.size() * offsets_.size();
    if (cache.xs.size() < n) cache.reserve(n);
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
      for (int dx : offsets_) {
        const int x = px + dx;
        if (x < 0 || x >= self_.width) continue;
        const cv::Vec3f& c = crow[x];
        const float l1 = std::abs(c[0] - center[0]) + std::abs(c[1] - center[1]) +
                         std::abs(c[2] - center[2]);
        const float w = weight_lut_[std::min(kLutSize - 1, static_cast<int>(l1 * kLutScale))];
        cache.xs[k] = static_cast<float>(x);
        cache.ys[k] = static_cast<float>(y);
        cache.weights[k] = w;
        cache.c0[k] = c[0];
        cache.c1[k] = c[1];
        cache.c2[k] = c[2];
        cache.row_offset[k] = y * color_stride;
        if (use_grad_) {
          cache.g0[k] = grow[x][0];
          cache.g1[k] = grow[x][1];
        }
        const bool has_prior = use_prior_ && prow[x] > 0.f;
        cache.priors[k] = has_prior ? prow[x] : 0.f;
        cache.prior_valid[k] = has_prior ? 1.f : 0.f;
        if (use_prior_ && !has_prior) cache.constant += w * wg_ * ldisp_;
        ++k;
      }
    }
    cache.count = k;
  }

  /// Aggregated cost C(p, plane) over the cached window; stops early (returning a value >= bound)
  /// once the partial sum exceeds `bound`. Written branch-free over chunks of samples so that the
  /// compiler vectorises it (gathers for the sub-pixel samples of the other view).
  float cost(const WindowCache& cache, const Plane& plane, float bound) const {
    return use_grad_ ? costImpl<true>(cache, plane, bound) : costImpl<false>(cache, plane, bound);
  }

  template <bool kGrad>
  float costImpl(const WindowCache& cache, const Plane& plane, float bound) const {
    float sum = cache.constant;
    if (sum >= bound) return sum;
    const float x_max = static_cast<float>(self_.width - 1);
    const float x_clamp = x_max - 1e-3f;  // keeps i0 + 1 inside the row
    const float* other = other_.color.ptr<float>(0);
    const float* other_grad = kGrad ? other_.grad.ptr<float>(0) : nullptr;
    const float sign = self_.match_sign;
    const float a = plane.a, b = plane.b, c = plane.c;
    const float* xs = cache.xs.data();
    const float* ys = cache.ys.data();
    const float* ws = cache.weights.data();
    const float* c0 = cache.c0.data();
    const float* c1 = cache.c1.data();
    const float* c2 = cache.c2.data();
    const float* g0 = cache.g0.data();
    const float* g1 = cache.g1.data();
    const float* pr = cache.priors.data();
    const float* pv = cache.prior_valid.data();
    const int* ro = cache.row_offset.data();
    // Early-exit checks once per window row's worth of samples: most refinement candidates are
    // worse than the current plane, and the partial sum often exceeds it after a row or two.
    const int chunk = static_cast<int>(offsets_.size());
    for (int start = 0; start < cache.count; start += chunk) {
      const int end = std::min(cache.count, start + chunk);
      float part = 0.f;
// (no `omp simd`: windows hold 9-25 samples, too few for 16-lane reductions to pay off)
      for (int k = start; k < end; ++k) {
        const float d = a * xs[k] + b * ys[k] + c;
        const float xm_raw = xs[k] + sign * d;
        const float inside = (xm_raw >= 0.f && xm_raw <= x_max) ? 1.f : 0.f;
        const float xm = std::min(std::max(xm_raw, 0.f), x_clamp);
        const int i0 = static_cast<int>(xm);
        const float f = xm - static_cast<float>(i0);
        const int idx = ro[k] + 3 * i0;
        const float m0 = other[idx] + f * (other[idx + 3] - other[idx]);
        const float m1 = other[idx + 1] + f * (other[idx + 4] - other[idx + 1]);
        const float m2 = other[idx + 2] + f * (other[idx + 5] - other[idx + 2]);
        const float col = std::abs(c0[k] - m0) + std::abs(c1[k] - m1) + std::abs(c2[k] - m2);
        float match = wa_ * std::min(col, lcol_);
        if (kGrad) {
          const int gi = (ro[k] / 3) * 2 + 2 * i0;
          const float h0 = other_grad[gi] + f * (other_grad[gi + 2] - other_grad[gi]);
          const float h1 = other_grad[gi + 1] + f * (other_grad[gi + 3] - other_grad[gi + 1]);
          match += wb_ * std::min(std::abs(g0[k] - h0) + std::abs(g1[k] - h1), lgrad_);
        }
        const float phi = inside * match + (1.f - inside) * outside_cost_ +
                          pv[k] * wg_ * std::min(std::abs(pr[k] - d), ldisp_);
        part += ws[k] * phi;
      }
      sum += part;
      if (sum >= bound) return sum;
    }
    return sum;
  }

  /// Whether disparity d at (x, y) is inside the search range of the pixel.
  bool admissible(int x, int y, float d) const {
    if (!(d >= self_.d_min && d <= self_.d_max)) return false;
    if (p_.use_lidar_bounds && self_.bounded(x, y)) {
      return d >= self_.lo(y, x) && d <= self_.hi(y, x);
    }
    return true;
  }

  /// Disparity interval [lo, hi] a random initial value is drawn from.
  void initRange(int x, int y, float& lo, float& hi) const {
    lo = self_.d_min;
    hi = self_.d_max;
    if (p_.use_lidar_bounds && self_.bounded(x, y)) {
      lo = std::max(lo, self_.lo(y, x));
      hi = std::min(hi, self_.hi(y, x));
      if (hi < lo) hi = lo;
    }
  }

  Plane randomPlane(int x, int y, Rng& rng) const {
    float lo, hi;
    initRange(x, y, lo, hi);
    float d = rng.uniform(lo, hi);
    const float prior = self_.prior.empty() ? 0.f : self_.prior(y, x);
    if (p_.init_from_prior && prior > 0.f && admissible(x, y, prior)) d = prior;
    if (!p_.slanted) return Plane{0.f, 0.f, d};
    if (p_.init_from_prior && p_.init_normal_from_prior && prior > 0.f) {
      Plane plane;
      if (priorSlope(x, y, plane)) {
        plane.c = d - plane.a * x - plane.b * y;
        return plane;
      }
    }
    float nx, ny, nz;
    randomNormal(rng, nx, ny, nz);
    return planeFromNormal(static_cast<float>(x), static_cast<float>(y), d, nx, ny, nz);
  }

  /// Slope (a, b) of the prior by central differences, when all four neighbours have a value and
  /// the slope is moderate (a plane, not a depth edge).
  bool priorSlope(int x, int y, Plane& plane) const {
    if (x < 1 || y < 1 || x >= self_.width - 1 || y >= self_.height - 1) return false;
    const cv::Mat1f& pr = self_.prior;
    const float l = pr(y, x - 1), r = pr(y, x + 1), u = pr(y - 1, x), dn = pr(y + 1, x);
    if (l <= 0.f || r <= 0.f || u <= 0.f || dn <= 0.f) return false;
    plane.a = 0.5f * (r - l);
    plane.b = 0.5f * (dn - u);
    return std::abs(plane.a) < kMaxSlope && std::abs(plane.b) < kMaxSlope;
  }

  void randomNormal(Rng& rng, float& nx, float& ny, float& nz) const {
    // Uniform direction on the hemisphere facing the camera, rejecting near-grazing planes.
    do {
      nx = rng.uniform(-1.f, 1.f);
      ny = rng.uniform(-1.f, 1.f);
      nz = rng.uniform(-1.f, 1.f);
      const float norm = std::sqrt(nx * nx + ny * ny + nz * nz);
      if (norm < 1e-3f || norm > 1.f) {
        nz = 0.f;
        continue;
      }
      nx /= norm;
      ny /= norm;
      nz = std::abs(nz) / norm;
    } while (nz < kMinNormalZ);
  }

  /// Spatial propagation + plane refinement of pixel (x, y) (one step of the sweep).
  void processPixel(int x, int y, bool forward, int iteration, WindowCache& cache) const {
    const int idx = y * self_.width + x;
    buildCache(x, y, cache);
    Plane best = self_.planes[idx];
    float best_cost = self_.cost[idx];
    const int step = forward ? -1 : 1;  // forward sweeps look left/up, backward right/down
    const int nxp = x + step, nyp = y + step;
    if (nxp >= 0 && nxp < self_.width) tryPlane(x, y, self_.planes[y * self_.width + nxp], cache, best, best_cost);
    if (nyp >= 0 && nyp < self_.height) tryPlane(x, y, self_.planes[nyp * self_.width + x], cache, best, best_cost);
    Rng rng(streamKey(p_.seed, self_.match_sign < 0 ? 0 : 1, iteration, idx));
    refine(x, y, cache, rng, best, best_cost);
    self_.planes[idx] = best;
    self_.cost[idx] = best_cost;
  }

  void tryPlane(int x, int y, const Plane& candidate, const WindowCache& cache, Plane& best,
                float& best_cost) const {
    // Propagation often offers (nearly) the plane the pixel already has: evaluating it cannot
    // change the result by more than the tolerance, so skip it.
    if (nearlySame(candidate, best, static_cast<float>(x), static_cast<float>(y))) return;
    if (!admissible(x, y, candidate.at(static_cast<float>(x), static_cast<float>(y)))) return;
    const float c = cost(cache, candidate, best_cost);
    if (c < best_cost) {
      best = candidate;
      best_cost = c;
    }
  }

  void refine(int x, int y, const WindowCache& cache, Rng& rng, Plane& best,
              float& best_cost) const {
    float dd;
    if (p_.use_lidar_bounds && self_.bounded(x, y)) {
      dd = std::max(self_.range(y, x), static_cast<float>(p_.min_refine_range));
    } else {
      dd = 0.5f * (self_.d_max - self_.d_min);
    }
    float dn = 1.f;
    const float fx = static_cast<float>(x), fy = static_cast<float>(y);
    while (dd >= kMinRefineStep) {
      const float d = best.at(fx, fy) + rng.uniform(-dd, dd);
      Plane candidate{0.f, 0.f, d};
      if (p_.slanted) {
        float nx, ny, nz;
        normalOf(best, nx, ny, nz);
        nx += rng.uniform(-dn, dn);
        ny += rng.uniform(-dn, dn);
        nz += rng.uniform(-dn, dn);
        const float norm = std::sqrt(nx * nx + ny * ny + nz * nz);
        if (norm > 1e-6f && std::abs(nz / norm) >= kMinNormalZ) {
          candidate = planeFromNormal(fx, fy, d, nx / norm, ny / norm, std::abs(nz) / norm);
          if (nz < 0.f) candidate = planeFromNormal(fx, fy, d, -nx / norm, -ny / norm, -nz / norm);
        } else {
          candidate = Plane{best.a, best.b, d - best.a * fx - best.b * fy};
        }
      }
      tryPlane(x, y, candidate, cache, best, best_cost);
      dd *= 0.5f;
      dn *= 0.5f;
    }
  }

 private:
  static constexpr int kLutSize = 4096;
  static constexpr float kLutScale = 4.f;        // LUT entries per unit of RGB L1 distance
  static constexpr float kMinNormalZ = 0.1f;     // rejects planes steeper than ~84 degrees
  static constexpr float kMaxSlope = 1.f;        // px of disparity per px
  static constexpr float kMinRefineStep = 0.1f;  // paper: stop when Delta_d_max < 0.1

  const PatchMatchParams& p_;
  ViewState& self_;
  const ViewState& other_;
  std::vector<int> offsets_;
  std::vector<float> weight_lut_;
  float wa_, wb_, wg_, lcol_, lgrad_, ldisp_, outside_cost_;
  bool use_grad_, use_prior_;
};

}  // namespace

void PatchMatchParams::validate() const {
  require(window_radius >= 1 && window_radius <= 50, "window_radius must be in [1, 50]");
  require(window_stride >= 1 && window_stride <= window_radius,
          "window_stride must be in [1, window_radius]");
  require(weight_delta > 0, "weight_delta must be > 0");
  require(alpha >= 0 && beta >= 0 && gamma >= 0, "alpha, beta, gamma must be >= 0");
  require(std::abs(alpha + beta + gamma - 1.0) < 1e-6, "alpha + beta + gamma must be 1");
  require(lambda_col > 0 && lambda_grad > 0 && lambda_disp > 0, "truncations must be > 0");
  require(iterations >= 0 && iterations <= 100, "iterations must be in [0, 100]");
  require(right_iterations == -1 || right_iterations >= 1,
          "right_iterations must be -1 (every iteration) or >= 1");
  require(bound_margin >= 0, "bound_margin must be >= 0");
  require(min_refine_range >= 0, "min_refine_range must be >= 0");
  require(min_disparity > 0, "min_disparity must be > 0");
  require(max_disparity > min_disparity, "max_disparity must be > min_disparity");
  require(lr_max_diff > 0, "lr_max_diff must be > 0");
  require(num_threads >= 0 && num_threads <= 256, "num_threads must be in [0, 256] (0 = all)");
}

/// Per-object buffers reused across frames (a fresh full-size buffer costs page faults every frame).
struct PatchMatchStereo::Scratch {
  ViewState left, right;
};

PatchMatchStereo::PatchMatchStereo(const PatchMatchParams& params) { setParams(params); }

void PatchMatchStereo::setParams(const PatchMatchParams& params) {
  params.validate();
  params_ = params;
}

namespace {

/// The image's disparity range [d_min, d_max] (METHOD.md: used where fewer than two scan lines
/// bound a pixel). With LiDAR bounds on, it is the range of the prior's disparities in this image
/// widened by bound_margin and clipped to [min_disparity, max_disparity]; otherwise the latter.
void imageRange(const ViewInput& in, const PatchMatchParams& p, float& d_min, float& d_max) {
  d_min = static_cast<float>(p.min_disparity);
  d_max = static_cast<float>(p.max_disparity);
  if (!p.use_lidar_bounds || in.prior.empty()) return;
  float lo = std::numeric_limits<float>::max(), hi = 0.f;
  for (const float d : in.prior) {
    if (d > 0.f) {
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
  }
  if (hi <= 0.f) return;
  const float margin = static_cast<float>(p.bound_margin);
  d_min = std::max(d_min, lo - margin);
  d_max = std::min(d_max, hi + margin);
  if (d_max <= d_min) d_max = d_min + 2.f * margin + 1e-3f;
}

void prepareView(const ViewInput& in, const PatchMatchParams& p, float match_sign, ViewState& v) {
  const bool use_grad = p.beta > 0;
  v.width = in.image.cols;
  v.height = in.image.rows;
  v.match_sign = match_sign;
  cv::Mat bgr;
  if (in.image.channels() == 1) {
    cv::cvtColor(in.image, bgr, cv::COLOR_GRAY2BGR);
  } else {
    bgr = in.image;
  }
  bgr.convertTo(v.color, CV_32FC3);
  if (use_grad) {
    cv::Mat grey, gx, gy;
    cv::cvtColor(v.color, grey, cv::COLOR_BGR2GRAY);
    // Central differences: (I(x+1) - I(x-1)) / 2.
    const cv::Mat kx = (cv::Mat_<float>(1, 3) << -0.5f, 0.f, 0.5f);
    cv::filter2D(grey, gx, CV_32F, kx, cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
    cv::filter2D(grey, gy, CV_32F, kx.t(), cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
    cv::merge(std::vector<cv::Mat>{gx, gy}, v.grad);
  } else {
    v.grad.release();
  }
  v.prior = in.prior;
  v.lo = in.bounds.lo;
  v.hi = in.bounds.hi;
  v.range = in.bounds.range;
  imageRange(in, p, v.d_min, v.d_max);
  v.planes.assign(static_cast<size_t>(v.width) * v.height, Plane{});
  v.cost.assign(static_cast<size_t>(v.width) * v.height, 0.f);
}

void checkInput(const ViewInput& v, const cv::Size& size, const char* which) {
  const std::string name(which);
  if (v.image.empty()) throw std::invalid_argument(name + " image is empty");
  if (v.image.depth() != CV_8U || (v.image.channels() != 1 && v.image.channels() != 3)) {
    throw std::invalid_argument(name + " image must be 8-bit BGR or grey");
  }
  if (v.image.size() != size) throw std::invalid_argument("left and right images differ in size");
  if (v.image.cols < 2 || v.image.rows < 1) throw std::invalid_argument(name + " image too small");
  if (!v.prior.empty() && v.prior.size() != size) {
    throw std::invalid_argument(name + " prior size differs from the image size");
  }
  const ScanLineBounds& b = v.bounds;
  if (!b.lo.empty() && (b.lo.size() != size || b.hi.size() != size || b.range.size() != size)) {
    throw std::invalid_argument(name + " scan-line bounds size differs from the image size");
  }
}

int threadCount(const PatchMatchParams& p) {
  return p.num_threads > 0 ? p.num_threads : omp_get_num_procs();
}

/// Initial planes and their costs.
void initialise(const Solver& solver, ViewState& v, const PatchMatchParams& p, int view) {
#pragma omp parallel for schedule(dynamic, 4) num_threads(threadCount(p))
  for (int y = 0; y < v.height; ++y) {
    WindowCache cache;
    for (int x = 0; x < v.width; ++x) {
      const int idx = y * v.width + x;
      Rng rng(streamKey(p.seed, view, -1, idx));
      v.planes[idx] = solver.randomPlane(x, y, rng);
      solver.buildCache(x, y, cache);
      v.cost[idx] = solver.cost(cache, v.planes[idx], std::numeric_limits<float>::max());
    }
  }
}

constexpr int kStripRows = 12;

/// One sweep of a view: strips in two phases, each strip in the paper's scan order.
void sweep(const Solver& solver, ViewState& v, const PatchMatchParams& p, int iteration) {
  const bool forward = iteration % 2 == 0;  // iterations 1, 3, ... (0-based even) go forward
  const int threads = threadCount(p);
  // The strip layout must not depend on the thread count, or results would.
  const int strip_rows = kStripRows;
  const int strips = (v.height + strip_rows - 1) / strip_rows;
  for (int phase = 0; phase < 2; ++phase) {
    const int parity = forward ? phase : 1 - phase;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int s = parity; s < strips; s += 2) {
      const int strip = forward ? s : strips - 1 - s;
      const int y0 = strip * strip_rows;
      const int y1 = std::min(v.height, y0 + strip_rows);
      WindowCache cache;
      if (forward) {
        for (int y = y0; y < y1; ++y)
          for (int x = 0; x < v.width; ++x) solver.processPixel(x, y, true, iteration, cache);
      } else {
        for (int y = y1 - 1; y >= y0; --y)
          for (int x = v.width - 1; x >= 0; --x) solver.processPixel(x, y, false, iteration, cache);
      }
    }
  }
}

/// View propagation: every pixel of `src` offers its plane to the pixel it matches in `dst`.
/// Rows are independent (a match stays in its row), so rows run in parallel.
void propagateView(const ViewState& src, const Solver& dst_solver, ViewState& dst,
                   const PatchMatchParams& p, bool left_to_right) {
#pragma omp parallel for schedule(dynamic, 4) num_threads(threadCount(p))
  for (int y = 0; y < src.height; ++y) {
    WindowCache cache;
    for (int x = 0; x < src.width; ++x) {
      const Plane& plane = src.planes[y * src.width + x];
      const float d = plane.at(static_cast<float>(x), static_cast<float>(y));
      const int xq = static_cast<int>(std::lround(x + src.match_sign * d));
      if (xq < 0 || xq >= dst.width) continue;
      const Plane moved = transferPlane(plane, left_to_right);
      const int idx = y * dst.width + xq;
      Plane best = dst.planes[idx];
      float best_cost = dst.cost[idx];
      if (nearlySame(best, moved, static_cast<float>(xq), static_cast<float>(y))) continue;
      if (!dst_solver.admissible(xq, y, moved.at(static_cast<float>(xq), static_cast<float>(y)))) {
        continue;
      }
      dst_solver.buildCache(xq, y, cache);
      dst_solver.tryPlane(xq, y, moved, cache, best, best_cost);
      dst.planes[idx] = best;
      dst.cost[idx] = best_cost;
    }
  }
}

cv::Mat1f disparityOf(const ViewState& v) {
  cv::Mat1f d(v.height, v.width);
  for (int y = 0; y < v.height; ++y) {
    for (int x = 0; x < v.width; ++x) {
      d(y, x) = v.planes[y * v.width + x].at(static_cast<float>(x), static_cast<float>(y));
    }
  }
  return d;
}

/// Left-right check: marks left pixels whose match disagrees by more than max_diff. A pixel whose
/// match falls outside the right image (the left border strip) cannot be checked and is kept.
cv::Mat1b leftRightCheck(const cv::Mat1f& left, const cv::Mat1f& right, float max_diff) {
  cv::Mat1b bad(left.size(), uchar(0));
  for (int y = 0; y < left.rows; ++y) {
    for (int x = 0; x < left.cols; ++x) {
      const float d = left(y, x);
      const int xr = static_cast<int>(std::lround(x - d));
      if (xr < 0 || xr >= right.cols) continue;
      if (std::abs(right(y, xr) - d) > max_diff) bad(y, x) = 255;
    }
  }
  return bad;
}

/// Fills inconsistent pixels. Where the up-sampled LiDAR prior has a value, the prior fills the
/// hole (the LiDAR saw the point; this is our reading for the fused method: Bleyer's background
/// fill assumes no other source). Elsewhere, the lower disparity of the nearest consistent planes
/// to the left and right (Bleyer et al.), smoothed by a colour-weighted median.
void fillHoles(const ViewState& v, cv::Mat1b bad, int radius, float delta, cv::Mat1f& disparity,
               int threads) {
  if (!v.prior.empty()) {
    for (int y = 0; y < v.height; ++y) {
      for (int x = 0; x < v.width; ++x) {
        if (bad(y, x) && v.prior(y, x) > 0.f) {
          disparity(y, x) = v.prior(y, x);
          bad(y, x) = 0;
        }
      }
    }
  }
  cv::Mat1f filled = disparity.clone();
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
  for (int y = 0; y < v.height; ++y) {
    for (int x = 0; x < v.width; ++x) {
      if (!bad(y, x)) continue;
      float best = std::numeric_limits<float>::max();
      int xl = x - 1;
      while (xl >= 0 && bad(y, xl)) --xl;
      int xr = x + 1;
      while (xr < v.width && bad(y, xr)) ++xr;
      const float fx = static_cast<float>(x), fy = static_cast<float>(y);
      if (xl >= 0) best = std::min(best, v.planes[y * v.width + xl].at(fx, fy));
      if (xr < v.width) best = std::min(best, v.planes[y * v.width + xr].at(fx, fy));
      filled(y, x) = best == std::numeric_limits<float>::max() ? 0.f : std::max(0.f, best);
    }
  }
  // Weighted median over the window of each filled pixel (weights exp(-L1 colour / delta)).
  std::vector<float> lut(1024);
  for (size_t i = 0; i < lut.size(); ++i) lut[i] = std::exp(-static_cast<float>(i) / delta);
  filled.copyTo(disparity);  // same size: no new allocation
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
  for (int y = 0; y < v.height; ++y) {
    std::vector<std::pair<float, float>> samples;
    for (int x = 0; x < v.width; ++x) {
      if (!bad(y, x)) continue;
      samples.clear();
      const cv::Vec3f& c = v.color(y, x);
      float total = 0.f;
      // Every second row and column of the window: the median barely changes, the cost quarters.
      for (int yy = std::max(0, y - radius); yy <= std::min(v.height - 1, y + radius); yy += 2) {
        const float* frow = filled.ptr<float>(yy);
        const cv::Vec3f* crow = v.color.ptr<cv::Vec3f>(yy);
        for (int xx = std::max(0, x - radius); xx <= std::min(v.width - 1, x + radius); xx += 2) {
          const float d = frow[xx];
          if (d <= 0.f) continue;
          const cv::Vec3f& q = crow[xx];
          const int l1 = static_cast<int>(std::abs(q[0] - c[0]) + std::abs(q[1] - c[1]) +
                                          std::abs(q[2] - c[2]));
          const float w = lut[std::min<int>(l1, static_cast<int>(lut.size()) - 1)];
          samples.emplace_back(d, w);
          total += w;
        }
      }
      if (samples.empty()) continue;
      std::sort(samples.begin(), samples.end());
      float acc = 0.f;
      for (const auto& s : samples) {
        acc += s.second;
        if (acc >= 0.5f * total) {
          disparity(y, x) = s.first;
          break;
        }
      }
    }
  }
}

}  // namespace

PatchMatchResult PatchMatchStereo::compute(const ViewInput& left, const ViewInput& right) {
  const cv::Size size = left.image.size();
  checkInput(left, size, "left");
  checkInput(right, size, "right");
  const PatchMatchParams& p = params_;
  if (!scratch_) scratch_ = std::make_shared<Scratch>();
  ViewState& lv = scratch_->left;
  ViewState& rv = scratch_->right;
  prepareView(left, p, -1.f, lv);
  prepareView(right, p, +1.f, rv);
  const bool two_views = p.view_propagation || p.lr_check;

  Solver left_solver(p, lv, rv);
  Solver right_solver(p, rv, lv);
  initialise(left_solver, lv, p, 0);
  if (two_views) initialise(right_solver, rv, p, 1);
  // The right view sweeps in the last `right_iterations` iterations only. It serves view
  // propagation and the left-right check; view propagation runs around its sweeps (left -> right
  // before, right -> left after), since in the other iterations the right view would only hand
  // the left view's own planes back.
  const int right_iterations = p.right_iterations < 0 ? p.iterations
                                                      : std::min(p.right_iterations, p.iterations);
  for (int it = 0; it < p.iterations; ++it) {
    sweep(left_solver, lv, p, it);
    if (!two_views || it < p.iterations - right_iterations) continue;
    if (p.view_propagation) propagateView(lv, right_solver, rv, p, true);
    sweep(right_solver, rv, p, it);
    if (p.view_propagation) propagateView(rv, left_solver, lv, p, false);
  }

  PatchMatchResult result;
  result.disparity = disparityOf(lv);
  result.planes.create(size);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const Plane& pl = lv.planes[y * size.width + x];
      result.planes(y, x) = cv::Vec3f(pl.a, pl.b, pl.c);
    }
  }
  if (two_views) result.right_disparity = disparityOf(rv);
  if (p.lr_check) {
    result.inconsistent =
        leftRightCheck(result.disparity, result.right_disparity, static_cast<float>(p.lr_max_diff));
    fillHoles(lv, result.inconsistent.clone(), std::max(p.window_radius, 5),
              static_cast<float>(p.weight_delta), result.disparity, threadCount(p));
  } else {
    result.inconsistent = cv::Mat1b(size, uchar(0));
  }
  // Non-positive or non-finite disparities (holes nothing could fill) are marked empty (0).
  for (float& d : cv::Mat_<float>(result.disparity)) {
    if (!(d > 0.f) || !std::isfinite(d)) d = 0.f;
  }
  return result;
}

}  // namespace lidar_stereo_fusion
