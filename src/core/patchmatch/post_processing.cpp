// PatchMatch post-processing: left-right check and hole filling (post_processing.h).
#include "lidar_stereo_fusion/core/patchmatch/post_processing.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace lidar_stereo_fusion {
namespace patchmatch {

namespace {

/// A window sample of the weighted median: disparity and weight.
struct Weighted {
  float d, w;
};

/// The colour-weighted median of s[i], i < n: the smallest d whose cumulative weight in
/// ascending order of d reaches `half` (half the total weight). A three-way quickselect, O(n) on
/// average; s is reordered.
float weightedMedian(Weighted* s, int n, float half) {
  int lo = 0, hi = n;  // the answer is among [lo, hi)
  float pivot = s[0].d;
  while (hi - lo > 1) {
    const float a = s[lo].d, b = s[lo + (hi - lo) / 2].d, c = s[hi - 1].d;
    pivot = std::max(std::min(a, b), std::min(std::max(a, b), c));  // median of three
    // [lo, lt) < pivot, [lt, gt) == pivot, [gt, hi) > pivot.
    int lt = lo, i = lo, gt = hi;
    float w_less = 0.f, w_equal = 0.f;
    while (i < gt) {
      if (s[i].d < pivot) {
        std::swap(s[i], s[lt]);
        w_less += s[lt].w;
        ++lt;
        ++i;
      } else if (s[i].d > pivot) {
        --gt;
        std::swap(s[i], s[gt]);
      } else {
        w_equal += s[i].w;
        ++i;
      }
    }
    if (w_less >= half && lt > lo) {
      hi = lt;
    } else if (w_less + w_equal >= half || gt == hi) {
      return pivot;
    } else {
      half -= w_less + w_equal;
      lo = gt;
    }
  }
  return hi - lo == 1 ? s[lo].d : pivot;
}

}  // namespace

cv::Mat1f disparityOf(const ViewState& v, int threads) {
  cv::Mat1f d(v.height, v.width);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int y = 0; y < v.height; ++y) {
    for (int x = 0; x < v.width; ++x) {
      d(y, x) = v.planes[y * v.width + x].at(static_cast<float>(x), static_cast<float>(y));
    }
  }
  return d;
}

cv::Mat1b leftRightCheck(const cv::Mat1f& left, const cv::Mat1f& right, float max_diff,
                         const std::vector<uint8_t>& keep, bool unmatched_bad, int threads) {
  cv::Mat1b bad(left.size(), uchar(0));
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int y = 0; y < left.rows; ++y) {
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
  return bad;
}

void fillHoles(const ViewState& v, cv::Mat1b bad, int radius, float delta, float fill_trust,
               float max_disparity, cv::Mat1f& disparity, int threads) {
  if (!v.prior.empty()) {
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int y = 0; y < v.height; ++y) {
      for (int x = 0; x < v.width; ++x) {
        if (bad(y, x) && v.prior(y, x) > 0.f && v.trust(y, x) >= fill_trust) {
          disparity(y, x) = v.prior(y, x);
          bad(y, x) = 0;
        }
      }
    }
  }
  cv::Mat1f filled = disparity.clone();
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
  for (int y = 0; y < v.height; ++y) {
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
      const int xl = left_good[x];
      const float fx = static_cast<float>(x), fy = static_cast<float>(y);
      for (const int xn : {xl, xr}) {
        if (xn < 0 || xn >= v.width) continue;
        const float d = v.planes[y * v.width + xn].at(fx, fy);
        if (d <= max_disparity) best = std::min(best, d);
      }
      filled(y, x) = best == std::numeric_limits<float>::max() ? 0.f : std::max(0.f, best);
    }
  }
  // Weighted median over the window of each filled pixel (weights exp(-L1 colour / delta)).
  std::vector<float> lut(1024);
  for (size_t i = 0; i < lut.size(); ++i) lut[i] = std::exp(-static_cast<float>(i) / delta);
  filled.copyTo(disparity);  // same size: no new allocation
  const int lut_last = static_cast<int>(lut.size()) - 1;
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
  for (int y = 0; y < v.height; ++y) {
    std::vector<Weighted> samples((radius + 1) * (radius + 1));  // radius / 2 + 1 per axis
    for (int x = 0; x < v.width; ++x) {
      if (!bad(y, x)) continue;
      const cv::Vec3f& c = v.color(y, x);
      float total = 0.f;
      int n = 0;
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
          const float w = lut[std::min(l1, lut_last)];
          samples[n++] = Weighted{d, w};
          total += w;
        }
      }
      if (n > 0) disparity(y, x) = weightedMedian(samples.data(), n, 0.5f * total);
    }
  }
}

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
