// Clouds without a usable ring field, made from a KITTI sweep whose rings the sweep order gives
// (the truth): shuffled, in image-row order, cropped to the camera's view, thinned to every k-th
// ring; and the agreement of recovered rings with the truth. For the ring recovery tests.
#pragma once

#include <algorithm>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "lidar_stereo_fusion/core/types.h"
#include "lidar_stereo_fusion/eval/sweep_order.h"
#include "lidar_stereo_fusion/io/kitti.h"

namespace lidar_stereo_fusion {
namespace test {

/// A cloud made from `base` (cloud[i] = base[order[i]]), its rings forgotten (-1); truth[i] is the
/// ring base[order[i]] had.
struct RingVariant {
  LidarCloud cloud;
  std::vector<int> truth;
};

inline RingVariant makeVariant(const LidarCloud& base, const std::vector<std::size_t>& order) {
  RingVariant out;
  out.cloud.reserve(order.size());
  out.truth.reserve(order.size());
  for (const std::size_t i : order) {
    out.cloud.push_back(base[i]);
    out.cloud.back().ring = -1;
    out.truth.push_back(base[i].ring);
  }
  return out;
}

/// Indices of the points of rings with ring % keep_every == 0 (all for keep_every 1), shuffled
/// with `seed` (shuffledIndices: the same swaps as std::shuffle of the list itself).
inline std::vector<std::size_t> shuffledOrder(const LidarCloud& base, unsigned seed,
                                              int keep_every = 1) {
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < base.size(); ++i) {
    if (base[i].ring % keep_every == 0) kept.push_back(i);
  }
  std::vector<std::size_t> order;
  order.reserve(kept.size());
  for (const std::size_t k : shuffledIndices(kept.size(), seed)) order.push_back(kept[k]);
  return order;
}

/// Image-row order (imageRowIndices); `crop` is what a depth-completion dataset gives: only the
/// points in view.
inline std::vector<std::size_t> imageRowOrder(const LidarCloud& base,
                                              const kitti::Calibration& calib, bool crop) {
  return imageRowIndices(base, calib.T_cam_velo, calib.camera, crop);
}

/// Agreement of recovered rings with the truth after the one relabelling: each recovered ring is
/// mapped to the true ring holding most of its points.
struct RingAgreement {
  double fraction = 0.0;    ///< points whose mapped ring is their true ring
  bool one_to_one = false;  ///< no two recovered rings map to one true ring
  bool reversed = false;    ///< mapped rings fall as recovered rings rise (KITTI counts top down)
  int true_rings = 0;       ///< distinct true rings among the points
};

inline RingAgreement ringAgreement(const LidarCloud& recovered, const std::vector<int>& truth) {
  std::map<int, std::map<int, int>> votes;  // recovered -> true -> points
  std::map<int, int> true_count;
  for (std::size_t i = 0; i < recovered.size(); ++i) {
    ++votes[recovered[i].ring][truth[i]];
    ++true_count[truth[i]];
  }
  RingAgreement out;
  out.true_rings = static_cast<int>(true_count.size());
  out.one_to_one = out.reversed = true;
  std::map<int, int> used;
  int agree = 0, previous = 1 << 30;
  for (const auto& [ring, by_truth] : votes) {
    const auto best =
        std::max_element(by_truth.begin(), by_truth.end(),
                         [](const auto& a, const auto& b) { return a.second < b.second; });
    agree += ring >= 0 ? best->second : 0;
    out.one_to_one = out.one_to_one && used[best->first]++ == 0;
    out.reversed = out.reversed && best->first < previous;
    previous = best->first;
  }
  out.fraction = recovered.empty() ? 0.0 : static_cast<double>(agree) / recovered.size();
  return out;
}

}  // namespace test
}  // namespace lidar_stereo_fusion
