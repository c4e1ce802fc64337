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

cv::Mat1f disparityOf(const ViewState& v) {
  cv::Mat1f d(v.height, v.width);
  for (int y = 0; y < v.height; ++y) {
    for (int x = 0; x < v.width; ++x) {
      d(y, x) = v.planes[y * v.width + x].at(static_cast<float>(x), static_cast<float>(y));
    }
  }
  return d;
}

cv::Mat1b leftRightCheck(const cv::Mat1f& left, const cv::Mat1f& right, float max_diff,
                         const std::vector<uint8_t>& keep, bool unmatched_bad) {
  cv::Mat1b bad(left.size(), uchar(0));
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
               cv::Mat1f& disparity, int threads) {
  if (!v.prior.empty()) {
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

}  // namespace patchmatch
}  // namespace lidar_stereo_fusion
