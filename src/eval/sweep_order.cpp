// The sweep with its order lost, for the KITTI protocols (eval/sweep_order.h).
#include "lidar_stereo_fusion/eval/sweep_order.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>
#include <tuple>

#include "lidar_stereo_fusion/eval/accuracy_protocols.h"

namespace lidar_stereo_fusion {

std::vector<std::string> sweepOrderNames() {
  return {"recorded", "shuffled", "image-rows", "image-rows-cropped"};
}

std::string sweepOrderName(SweepOrder order) {
  return sweepOrderNames().at(static_cast<std::size_t>(order));
}

SweepOrder parseSweepOrder(const std::string& name) {
  const std::vector<std::string> names = sweepOrderNames();
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) {
    throw std::invalid_argument("unknown sweep order '" + name + "' (valid: " + joinedNames(names) +
                                ")");
  }
  return static_cast<SweepOrder>(it - names.begin());
}

std::vector<std::size_t> shuffledIndices(std::size_t n, unsigned seed) {
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::mt19937 rng(seed);
  std::shuffle(order.begin(), order.end(), rng);
  return order;
}

std::vector<std::size_t> imageRowIndices(const LidarCloud& cloud,
                                         const Eigen::Isometry3d& T_cam_lidar,
                                         const StereoCamera& camera, bool crop) {
  camera.validate();
  std::vector<std::tuple<int, int, std::size_t>> in_view;
  std::vector<std::size_t> outside;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p = T_cam_lidar * Eigen::Vector3d(cloud[i].x, cloud[i].y, cloud[i].z);
    const double col = std::floor(camera.fx * p.x() / p.z() + camera.cx + 0.5);
    const double row = std::floor(camera.fy * p.y() / p.z() + camera.cy + 0.5);
    // (NaN fails every comparison: a non-finite point is outside.)
    if (p.z() >= 0.5 && col >= 0 && col < camera.width && row >= 0 && row < camera.height) {
      in_view.emplace_back(static_cast<int>(row), static_cast<int>(col), i);
    } else {
      outside.push_back(i);
    }
  }
  std::sort(in_view.begin(), in_view.end());
  std::vector<std::size_t> order;
  order.reserve(in_view.size() + (crop ? 0 : outside.size()));
  for (const auto& entry : in_view) order.push_back(std::get<2>(entry));
  if (!crop) order.insert(order.end(), outside.begin(), outside.end());
  return order;
}

ReorderedSweep reorderSweep(const LidarCloud& cloud, SweepOrder order,
                            const Eigen::Isometry3d& T_cam_lidar, const StereoCamera& camera,
                            int num_rings, unsigned seed) {
  if (num_rings < 1) {
    throw std::invalid_argument("reorderSweep: num_rings must be >= 1, got " +
                                std::to_string(num_rings));
  }
  ReorderedSweep out;
  if (order == SweepOrder::kRecorded) {
    out.cloud = cloud;
    out.rings.rings = countRings(cloud);
    return out;
  }
  const std::vector<std::size_t> indices =
      order == SweepOrder::kShuffled
          ? shuffledIndices(cloud.size(), seed)
          : imageRowIndices(cloud, T_cam_lidar, camera, order == SweepOrder::kImageRowsCropped);
  out.cloud.reserve(indices.size());
  for (const std::size_t i : indices) {
    out.cloud.push_back(cloud[i]);
    out.cloud.back().ring = -1;
  }
  out.rings = ensureRings(out.cloud, /*has_ring_field=*/false, num_rings);
  return out;
}

}  // namespace lidar_stereo_fusion
