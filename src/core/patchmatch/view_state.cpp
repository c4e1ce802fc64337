// PatchMatch: preparing one view's state (see view_state.h).
#include "lidar_stereo_fusion/core/patchmatch/view_state.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "lidar_stereo_fusion/core/patchmatch/cost_kernel.h"

namespace lidar_stereo_fusion {
namespace patchmatch {

namespace {

constexpr float kMaxPriorSlope = 1.f;  // [px of disparity per px]

/// The image's disparity range [d_min, d_max], used where fewer than two scan lines bound a pixel
/// (METHOD.md). The paper's reading (LiDAR bounds on, no confidence weighting): the range of this
/// frame's prior widened by bound_margin, clipped to [min_disparity, max_disparity]. Otherwise,
/// and in particular with confidence weighting (the images must be free to find what the LiDAR did
/// not see, e.g. near objects above its field of view): [min_disparity, max_disparity].
void imageRange(const ViewInput& in, const PatchMatchParams& p, float& d_min, float& d_max) {
  d_min = static_cast<float>(p.min_disparity);
  d_max = static_cast<float>(p.max_disparity);
  if (!p.use_lidar_bounds || p.confidence_weighting || in.prior.empty()) return;
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

/// The view's colour (v.color), smoothed by a 3x3 Gaussian of sigma `smoothing` [px] if > 0
/// (PatchMatchParams::image_smoothing), and, if use_grad, the gradients of its grey image
/// (central differences, (I(x+1) - I(x-1)) / 2; else left empty), which only the texels keep.
void prepareImages(const ViewInput& in, double smoothing, bool use_grad, ViewState& v,
                   cv::Mat1f& gx, cv::Mat1f& gy) {
  cv::Mat bgr;
  if (in.image.channels() == 1) {
    cv::cvtColor(in.image, bgr, cv::COLOR_GRAY2BGR);
  } else {
    bgr = in.image;
  }
  bgr.convertTo(v.color, CV_32FC3);
  if (smoothing > 0) {
    cv::GaussianBlur(v.color, v.color, cv::Size(3, 3), smoothing, smoothing, cv::BORDER_REPLICATE);
  }
  if (!use_grad) return;
  cv::Mat grey;
  cv::cvtColor(v.color, grey, cv::COLOR_BGR2GRAY);
  const cv::Mat kx = (cv::Mat_<float>(1, 3) << -0.5f, 0.f, 0.5f);
  cv::filter2D(grey, gx, CV_32F, kx, cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
  cv::filter2D(grey, gy, CV_32F, kx.t(), cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
}

/// v rounded half away from zero (std::lround's rule without its library call).
short toFixed(float v) { return static_cast<short>(v + (v < 0.f ? -0.5f : 0.5f)); }

/// The texels of the cost (view_state.h, cost_kernel.h): colour and gradient (gx, gy; 0 where
/// empty) interleaved in 16-bit fixed point, padded to 8 channels.
void prepareTexels(const cv::Mat1f& gx, const cv::Mat1f& gy, ViewState& v) {
  // Every entry is written below: the buffer of the previous frame is reused as it is.
  v.texels.resize(static_cast<size_t>(v.width) * v.height);
  const float scale = static_cast<float>(kTexelScale);
  for (int y = 0; y < v.height; ++y) {
    const cv::Vec3f* crow = v.color.ptr<cv::Vec3f>(y);
    const float* gxrow = gx.empty() ? nullptr : gx[y];
    const float* gyrow = gy.empty() ? nullptr : gy[y];
    Texel* row = &v.texels[static_cast<size_t>(y) * v.width];
    for (int x = 0; x < v.width; ++x) {
      short* t = row[x].v;
      // Colours 0..255: exact if whole numbers (no image_smoothing), else to 1/64. |gradient| <=
      // 127.5 (half a grey difference): at most 8160 in fixed point. Rounded half away from zero.
      for (int c = 0; c < 3; ++c) t[c] = toFixed(crow[x][c] * scale);
      t[3] = 0;
      t[4] = gxrow != nullptr ? toFixed(gxrow[x] * scale) : 0;
      t[5] = gyrow != nullptr ? toFixed(gyrow[x] * scale) : 0;
      t[6] = 0;
      t[7] = 0;
    }
  }
}

/// trust: the prior's confidence (confidence weighting) or 1 where the prior has a value.
void prepareTrust(const ViewInput& in, const PatchMatchParams& p, ViewState& v) {
  if (in.prior.empty()) {
    v.trust.release();
    return;
  }
  v.trust.create(in.prior.size());
  const bool use_confidence = p.confidence_weighting && !in.confidence.empty();
  for (int y = 0; y < in.prior.rows; ++y) {
    const float* pr = in.prior[y];
    const float* co = use_confidence ? in.confidence[y] : nullptr;
    float* t = v.trust[y];
    for (int x = 0; x < in.prior.cols; ++x) {
      const float c = co ? std::min(1.f, std::max(0.f, co[x])) : 1.f;
      t[x] = pr[x] > 0.f ? c : 0.f;
    }
  }
}

}  // namespace

bool priorSlope(const ViewState& v, int x, int y, float& a, float& b) {
  if (x < 1 || y < 1 || x >= v.width - 1 || y >= v.height - 1) return false;
  const cv::Mat1f& pr = v.prior;
  const float l = pr(y, x - 1), r = pr(y, x + 1), u = pr(y - 1, x), dn = pr(y + 1, x);
  if (l <= 0.f || r <= 0.f || u <= 0.f || dn <= 0.f) return false;
  a = 0.5f * (r - l);
  b = 0.5f * (dn - u);
  return std::abs(a) < kMaxPriorSlope && std::abs(b) < kMaxPriorSlope;
}

namespace {

/// Slope of the prior along one axis at value d from the neighbours before (p) and after (n):
/// central when both have a value, one-sided when one has, 0 when none has; 0 when steeper than
/// kMaxPriorSlope (a depth edge).
float axisSlope(float p, float d, float n) {
  float s = 0.f;
  if (p > 0.f && n > 0.f) {
    s = 0.5f * (n - p);
  } else if (n > 0.f) {
    s = n - d;
  } else if (p > 0.f) {
    s = d - p;
  }
  return std::abs(s) < kMaxPriorSlope ? s : 0.f;
}

}  // namespace

Plane priorPlane(const ViewState& v, int x, int y) {
  const cv::Mat1f& pr = v.prior;
  const float d = pr(y, x);
  const float l = x > 0 ? pr(y, x - 1) : 0.f, r = x + 1 < v.width ? pr(y, x + 1) : 0.f;
  const float u = y > 0 ? pr(y - 1, x) : 0.f, dn = y + 1 < v.height ? pr(y + 1, x) : 0.f;
  const float a = axisSlope(l, d, r), b = axisSlope(u, d, dn);
  return Plane{a, b, d - a * x - b * y};
}

void prepareView(const ViewInput& in, const PatchMatchParams& p, float match_sign, ViewState& v) {
  v.width = in.image.cols;
  v.height = in.image.rows;
  v.match_sign = match_sign;
  cv::Mat1f gx, gy;
  prepareImages(in, p.image_smoothing, p.beta > 0, v, gx, gy);
  prepareTexels(gx, gy, v);
  preparePrior(in, p, v);
  const size_t n = static_cast<size_t>(v.width) * v.height;
  // Planes, costs and offers are written before they are read (initialise, offerView): the
  // previous frame's buffers are reused as they are; flags start cleared.
  v.planes.resize(n);
  v.cost.resize(n);
  v.offer.resize(n);
  v.offered.assign(n, 0);
  v.guide.clear();
}

void preparePrior(const ViewInput& in, const PatchMatchParams& p, ViewState& v) {
  v.width = in.image.cols;
  v.height = in.image.rows;
  v.prior = in.prior;
  prepareTrust(in, p, v);
  v.lo = in.bounds.lo;
  v.hi = in.bounds.hi;
  v.range = in.bounds.range;
  imageRange(in, p, v.d_min, v.d_max);
  v.locked.assign(static_cast<size_t>(v.width) * v.height, 0);
  const float lock = static_cast<float>(p.lock_confidence);
  if (v.trust.empty() || !p.confidence_weighting || lock > 1.f) return;
  for (int y = 0; y < v.height; ++y) {
    const float* t = v.trust[y];
    for (int x = 0; x < v.width; ++x) v.locked[y * v.width + x] = t[x] >= lock ? kLockedToPrior : 0;
  }
}

void setGuide(std::vector<Plane> guide, const PatchMatchParams& p, ViewState& v) {
  v.guide = std::move(guide);
  // A level finer than unbounded_scale takes the level below's plane as it is; else, without
  // full_size_unbounded, it polishes that plane.
  const uint8_t settle = p.unbounded_scale > 1   ? kKeptFromGuide
                         : p.full_size_unbounded ? uint8_t{0}
                                                 : kSettledByGuide;
  if (settle == 0) return;
  for (int y = 0; y < v.height; ++y) {
    for (int x = 0; x < v.width; ++x) {
      uint8_t& l = v.locked[y * v.width + x];
      if (l == 0 && !v.bounded(x, y)) l = settle;
    }
  }
}

void leaveToFill(const cv::Mat1b& inconsistent, ViewState& v) {
  for (int y = 0; y < v.height; ++y) {
    const uchar* bad = inconsistent[y];
    for (int x = 0; x < v.width; ++x) {
      uint8_t& l = v.locked[y * v.width + x];
      if (bad[x] && l != kLockedToPrior && !v.bounded(x, y)) l = kLeftToFill;
    }
  }
}

void checkViewInput(const ViewInput& v, const cv::Size& size, const char* which) {
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
  if (!v.confidence.empty() && v.confidence.size() != size) {
    throw std::invalid_argument(name + " confidence size differs from the image size");
  }
  const ScanLineBounds& b = v.bounds;
  if (!b.lo.empty() && (b.lo.size() != size || b.hi.size() != size || b.range.size() != size)) {
    throw std::invalid_argument(name + " scan-line bounds size differs from the image size");
  }
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
