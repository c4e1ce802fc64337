// PatchMatch post-processing: left-right check and hole filling (post_processing.h).
#include "lidar_stereo_fusion/core/patchmatch/post_processing.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "lidar_stereo_fusion/core/patchmatch/coarse_to_fine.h"
#include "lidar_stereo_fusion/core/patchmatch/median_kernel.h"
#include "lidar_stereo_fusion/core/patchmatch/parallel.h"

namespace lidar_stereo_fusion {
namespace patchmatch {

namespace {

/// The colour-weighted median of d[i], i < n: the smallest d[i] whose cumulative weight, the sum
/// of w[j] over d[j] <= d[i], reaches `half` (half the total weight). Each candidate's sum runs
/// over every sample in window order, kMedianLanes candidates side by side, without branches:
/// for the few dozen samples of a window faster than a quickselect, whose branches the data
/// decide (with AVX2 or AVX-512 where the CPU has it: the same floats). The arrays have room
/// for n rounded up to kMedianLanes; the padding is written here.
float weightedMedian(float* d, float* w, int n, float half, SimdPath path) {
  const int padded = (n + kMedianLanes - 1) / kMedianLanes * kMedianLanes;
  // Padding: the largest value, and the largest real sample always qualifies (its sum is all).
  for (int i = n; i < padded; ++i) {
    d[i] = std::numeric_limits<float>::max();
    w[i] = 0.f;
  }
  if (path == SimdPath::kAvx512) return weightedMedianAvx512(d, w, n, padded, half);
  if (path == SimdPath::kAvx2) return weightedMedianAvx2(d, w, n, padded, half);
  float best = std::numeric_limits<float>::max();
  for (int i0 = 0; i0 < padded; i0 += kMedianLanes) {
    const float* candidate = d + i0;
    float cumulative[kMedianLanes] = {};
    for (int j = 0; j < n; ++j) {
      const float dj = d[j], wj = w[j];
      for (int k = 0; k < kMedianLanes; ++k) cumulative[k] += dj <= candidate[k] ? wj : 0.f;
    }
    for (int k = 0; k < kMedianLanes; ++k) {
      if (cumulative[k] >= half && candidate[k] < best) best = candidate[k];
    }
  }
  return best;
}

}  // namespace

cv::Mat1f disparityOf(const ViewState& v, int threads) {
  cv::Mat1f d(v.height, v.width);
  parallelRows(v.height, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      for (int x = 0; x < v.width; ++x) {
        d(y, x) = v.planes[y * v.width + x].at(static_cast<float>(x), static_cast<float>(y));
      }
    }
  });
  return d;
}

cv::Mat1b leftRightCheck(const cv::Mat1f& left, const cv::Mat1f& right, float max_diff,
                         const std::vector<uint8_t>& keep, bool unmatched_bad, int threads) {
  cv::Mat1b bad(left.size(), uchar(0));
  parallelRows(left.rows, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      for (int x = 0; x < left.cols; ++x) {
        if (!keep.empty() && keep[y * left.cols + x]) continue;
        const float d = left(y, x);
        const int xr = static_cast<int>(std::lround(x - d));
        if (xr < 0 || xr >= right.cols) {
          if (unmatched_bad) bad(y, x) = 255;
          continue;
        }
        if (std::abs(right(y, xr) - d) > max_diff) bad(y, x) = 255;
      }
    }
  });
  return bad;
}

namespace {

/// Whether the view's prior fills pixel (x, y): it has a value there, trusted >= fill_trust.
inline bool priorFills(const ViewState& v, int x, int y, float fill_trust) {
  return v.prior(y, x) > 0.f && v.trust(y, x) >= fill_trust;
}

/// The fill's first step: where the prior is sure, the bad pixels take it and are no longer bad.
void fillFromPrior(const ViewState& v, cv::Mat1b& bad, float fill_trust, cv::Mat1f& disparity,
                   int threads) {
  if (v.prior.empty()) return;
  parallelRows(v.height, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      for (int x = 0; x < v.width; ++x) {
        if (bad(y, x) && priorFills(v, x, y, fill_trust)) {
          disparity(y, x) = v.prior(y, x);
          bad(y, x) = 0;
        }
      }
    }
  });
}

/// Bleyer's fill of row y: each bad pixel takes the lower (background) disparity of the planes of
/// the nearest consistent pixels left and right, extended to it (0 where neither qualifies).
void fillRowFromBackground(const ViewState& v, const cv::Mat1b& bad, int y, float max_disparity,
                           float* filled) {
  // The nearest consistent pixel to the left of each pixel, found in one pass (-1: none).
  std::vector<int> left_good(v.width);
  int last = -1;
  for (int x = 0; x < v.width; ++x) {
    left_good[x] = last;
    if (!bad(y, x)) last = x;
  }
  int xr = v.width;  // the nearest consistent pixel to the right (width: none)
  for (int x = v.width - 1; x >= 0; --x) {
    if (!bad(y, x)) {
      xr = x;
      continue;
    }
    // A neighbour's plane extended to this pixel fills it only up to max_disparity: at the
    // image border one side is missing, and a slanted plane extrapolated far can pass it.
    float best = std::numeric_limits<float>::max();
    const float fx = static_cast<float>(x), fy = static_cast<float>(y);
    for (const int xn : {left_good[x], xr}) {
      if (xn < 0 || xn >= v.width) continue;
      const float d = v.planes[y * v.width + xn].at(fx, fy);
      if (d <= max_disparity) best = std::min(best, d);
    }
    filled[x] = best == std::numeric_limits<float>::max() ? 0.f : std::max(0.f, best);
  }
}

/// The median's weights exp(-L1 colour / delta), tabulated per unit of RGB L1 distance.
std::vector<float> colourWeightTable(float delta) {
  std::vector<float> lut(1024);
  for (size_t i = 0; i < lut.size(); ++i) lut[i] = std::exp(-static_cast<float>(i) / delta);
  return lut;
}

/// The window of pixel (x, y) for its weighted median: the filled disparities > 0 on every second
/// row and column within `radius` (the median barely changes, the cost quarters) into ds, their
/// colour weights into ws. Returns how many; `total` is their weights' sum.
int medianWindow(const ViewState& v, const cv::Mat1f& filled, int x, int y, int radius,
                 const std::vector<float>& lut, float* ds, float* ws, float& total) {
  const cv::Vec3f& c = v.color(y, x);
  const int lut_last = static_cast<int>(lut.size()) - 1;
  total = 0.f;
  int n = 0;
  for (int yy = std::max(0, y - radius); yy <= std::min(v.height - 1, y + radius); yy += 2) {
    const float* frow = filled.ptr<float>(yy);
    const cv::Vec3f* crow = v.color.ptr<cv::Vec3f>(yy);
    for (int xx = std::max(0, x - radius); xx <= std::min(v.width - 1, x + radius); xx += 2) {
      const float d = frow[xx];
      if (d <= 0.f) continue;
      const cv::Vec3f& q = crow[xx];
      const int l1 =
          static_cast<int>(std::abs(q[0] - c[0]) + std::abs(q[1] - c[1]) + std::abs(q[2] - c[2]));
      const float w = lut[std::min(l1, lut_last)];
      ds[n] = d;
      ws[n++] = w;
      total += w;
    }
  }
  return n;
}

/// The fill's last step: each bad pixel takes the colour-weighted median of `filled` over its
/// window (medianWindow); a window without any fill leaves the pixel as it is.
void weightedMedianFilter(const ViewState& v, const cv::Mat1b& bad, const cv::Mat1f& filled,
                          const FillOptions& o, cv::Mat1f& disparity, int threads) {
  const std::vector<float> lut = colourWeightTable(o.delta);
  parallelRows(v.height, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      // At most radius + 1 samples per axis (every second of 2 radius + 1), and the padding.
      const int most = (o.radius + 1) * (o.radius + 1);
      std::vector<float> ds(most + kMedianLanes), ws(most + kMedianLanes);
      for (int x = 0; x < v.width; ++x) {
        if (!bad(y, x)) continue;
        float total;
        const int n = medianWindow(v, filled, x, y, o.radius, lut, ds.data(), ws.data(), total);
        if (n > 0) disparity(y, x) = weightedMedian(ds.data(), ws.data(), n, 0.5f * total, o.simd);
      }
    }
  });
}

}  // namespace

namespace {

/// One row of resultFromLevelBelow.
void resultFromLevelBelowRow(const ViewState& v, const PatchMatchResult& below, int scale,
                             bool lr_check, float fill_trust, int y, PatchMatchResult& out) {
  const bool with_planes = !out.planes.empty();
  const bool has_prior = !v.prior.empty();
  const float s = static_cast<float>(scale);
  const int yb = std::min(below.planes.rows - 1, y / scale);
  const cv::Vec3f* below_planes = below.planes[yb];
  const float* below_disparity = below.disparity[yb];
  const uchar* below_bad = lr_check ? below.inconsistent[yb] : nullptr;
  cv::Vec3f* planes = with_planes ? out.planes[y] : nullptr;
  float* disparity = out.disparity[y];
  uchar* bad = out.inconsistent[y];
  for (int x = 0; x < v.width; ++x) {
    const int xb = std::min(below.planes.cols - 1, x / scale);
    const bool locked = v.locked[y * v.width + x] == kLockedToPrior;
    const Plane plane = locked ? priorPlane(v, x, y) : upsampledPlane(below_planes[xb], s);
    if (with_planes) planes[x] = cv::Vec3f(plane.a, plane.b, plane.c);
    float d = plane.at(static_cast<float>(x), static_cast<float>(y));
    // The LiDAR measured a locked pixel: the check keeps it.
    bad[x] = !locked && below_bad != nullptr && below_bad[xb] ? 255 : 0;
    if (bad[x])
      d = has_prior && priorFills(v, x, y, fill_trust) ? v.prior(y, x) : s * below_disparity[xb];
    disparity[x] = d > 0.f && std::isfinite(d) ? d : 0.f;  // empty: nothing could fill it
  }
}

}  // namespace

PatchMatchResult resultFromLevelBelow(const ViewState& v, const PatchMatchResult& below, int scale,
                                      bool lr_check, float fill_trust, bool planes, int threads) {
  const cv::Size size(v.width, v.height);
  PatchMatchResult out;
  if (planes) out.planes.create(size);
  out.disparity.create(size);
  out.inconsistent.create(size);
  parallelRows(size.height, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      resultFromLevelBelowRow(v, below, scale, lr_check, fill_trust, y, out);
    }
  });
  return out;
}

void fillHoles(const ViewState& v, cv::Mat1b bad, const FillOptions& options, cv::Mat1f& disparity,
               int threads) {
  fillFromPrior(v, bad, options.fill_trust, disparity, threads);
  cv::Mat1f filled = disparity.clone();
  parallelRows(v.height, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      fillRowFromBackground(v, bad, y, options.max_disparity, filled[y]);
    }
  });
  filled.copyTo(disparity);  // same size: no new allocation
  weightedMedianFilter(v, bad, filled, options, disparity, threads);
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
