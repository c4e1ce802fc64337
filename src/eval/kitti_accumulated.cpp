// The accumulated KITTI depth reference: posed sweeps, z-buffer, removal against the own sweep.
#include "lidar_stereo_fusion/eval/kitti_accumulated.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "lidar_stereo_fusion/io/kitti_oxts.h"

namespace lidar_stereo_fusion {
namespace kitti {
namespace {

namespace fs = std::filesystem;

constexpr float kNoDepth = std::numeric_limits<float>::infinity();

/// Projects every point in range into `depth` (nearest wins; `depth` holds kNoDepth where empty).
/// `keep`, when given, decides per projected point (u, v, z) whether it enters.
template <typename Keep>
void zBuffer(const PosedSweep& sweep, const StereoCamera& camera, const AccumulationParams& params,
             cv::Mat1f& depth, Keep keep) {
  const Eigen::Matrix3d R = sweep.T_cam_lidar.linear();
  const Eigen::Vector3d t = sweep.T_cam_lidar.translation();
  for (const LidarPoint& point : sweep.cloud) {
    const Eigen::Vector3d p = R * Eigen::Vector3d(point.x, point.y, point.z) + t;
    if (!p.allFinite() || p.z() < params.min_depth || p.z() > params.max_depth) continue;
    // Same pixel rule as projectCloud: pixel i covers [i - 0.5, i + 0.5).
    const double u = std::floor(camera.fx * p.x() / p.z() + camera.cx + 0.5);
    const double v = std::floor(camera.fy * p.y() / p.z() + camera.cy + 0.5);
    if (u < 0 || v < 0 || u >= camera.width || v >= camera.height) continue;
    const int x = static_cast<int>(u), y = static_cast<int>(v);
    const float z = static_cast<float>(p.z());
    if (!keep(x, y, z)) continue;
    depth(y, x) = std::min(depth(y, x), z);
  }
}

cv::Mat1f emptyDepth(const StereoCamera& camera) {
  return cv::Mat1f(camera.height, camera.width, kNoDepth);
}

/// kNoDepth -> 0.
cv::Mat1f toReference(const cv::Mat1f& depth) {
  cv::Mat1f out = depth.clone();
  out.setTo(0.f, depth == kNoDepth);
  return out;
}

/// Median and 90th percentile of |z_other - z_own| / z_own where both have a point.
void compare(const cv::Mat1f& own, const cv::Mat1f& other, AccumulatedDepth& out) {
  std::vector<double> rel;
  for (int y = 0; y < own.rows; ++y) {
    for (int x = 0; x < own.cols; ++x) {
      if (own(y, x) == kNoDepth || other(y, x) == kNoDepth) continue;
      rel.push_back(std::abs(other(y, x) - own(y, x)) / own(y, x));
    }
  }
  out.compared_pixels = static_cast<int>(rel.size());
  if (rel.empty()) return;
  auto quantile = [&rel](double q) {
    auto it = rel.begin() + static_cast<long>(q * (rel.size() - 1));
    std::nth_element(rel.begin(), it, rel.end());
    return *it;
  };
  out.median_relative_difference = quantile(0.5);
  out.p90_relative_difference = quantile(0.9);
}

/// The depth most of `votes` (one per sweep) agree on: the largest group [z, z (1 + tolerance)]
/// of the sorted votes, the nearer between equal groups; the group's median.
float majorityDepth(std::vector<float>& votes, double tolerance) {
  std::sort(votes.begin(), votes.end());
  std::size_t best_first = 0, best_count = 0;
  for (std::size_t i = 0; i < votes.size(); ++i) {
    const auto end = std::upper_bound(votes.begin() + static_cast<long>(i), votes.end(),
                                      static_cast<float>(votes[i] * (1.0 + tolerance)));
    const std::size_t count = static_cast<std::size_t>(end - votes.begin()) - i;
    if (count > best_count) {
      best_first = i;
      best_count = count;
    }
  }
  const std::size_t mid = best_first + best_count / 2;
  return best_count % 2 == 1 ? votes[mid] : 0.5f * (votes[mid - 1] + votes[mid]);
}

/// AccumulationParams::Combine::kMajority over the per-sweep z-buffers `layers`.
cv::Mat1f majorityOf(const std::vector<cv::Mat1f>& layers, double tolerance) {
  cv::Mat1f out(layers.front().size(), kNoDepth);
  std::vector<float> votes;
  for (int y = 0; y < out.rows; ++y) {
    for (int x = 0; x < out.cols; ++x) {
      votes.clear();
      for (const cv::Mat1f& layer : layers) {
        if (layer(y, x) != kNoDepth) votes.push_back(layer(y, x));
      }
      if (!votes.empty()) out(y, x) = majorityDepth(votes, tolerance);
    }
  }
  return out;
}

}  // namespace

void AccumulationParams::validate() const {
  auto fail = [](const std::string& what) {
    throw std::invalid_argument("AccumulationParams: " + what);
  };
  if (half_span < 0) fail("half_span must be >= 0");
  if (!(min_depth > 0) || !(max_depth > min_depth)) fail("need 0 < min_depth < max_depth");
  if (check_half_width < 0 || check_half_height < 0) fail("check window half sizes must be >= 0");
  if (!(tolerance >= 0 && tolerance < 1)) fail("tolerance must be in [0, 1)");
}

AccumulatedDepth accumulateDepth(const std::vector<PosedSweep>& sweeps, const StereoCamera& camera,
                                 const AccumulationParams& params) {
  camera.validate();
  params.validate();
  const long owners =
      std::count_if(sweeps.begin(), sweeps.end(), [](const PosedSweep& s) { return s.own; });
  if (owners != 1) {
    throw std::invalid_argument("accumulateDepth: exactly one sweep must be the own one, got " +
                                std::to_string(owners));
  }
  const auto always = [](int, int, float) { return true; };
  cv::Mat1f own = emptyDepth(camera);
  for (const PosedSweep& s : sweeps) {
    if (s.own) zBuffer(s, camera, params, own, always);
  }
  // The own sweep's depth range around every pixel: erosion (min) of the depths with empty =
  // +inf, dilation (max) with empty = 0.
  const cv::Mat kernel = cv::getStructuringElement(
      cv::MORPH_RECT, {2 * params.check_half_width + 1, 2 * params.check_half_height + 1});
  cv::Mat1f z_min, z_max, own_zero = toReference(own);
  cv::erode(own, z_min, kernel);
  cv::dilate(own_zero, z_max, kernel);

  AccumulatedDepth out;
  out.sweeps = static_cast<int>(sweeps.size());
  out.unverified_kept = params.keep_unverified;
  cv::Mat1f other_raw = emptyDepth(camera), kept = emptyDepth(camera);
  std::vector<cv::Mat1f> layers{own};  // kMajority: one z-buffer per sweep
  const double lo = 1.0 - params.tolerance, hi = 1.0 + params.tolerance;
  for (const PosedSweep& s : sweeps) {
    if (s.own) continue;
    zBuffer(s, camera, params, other_raw, always);
    if (params.combine == AccumulationParams::Combine::kMajority)
      layers.push_back(emptyDepth(camera));
    cv::Mat1f& into =
        params.combine == AccumulationParams::Combine::kMajority ? layers.back() : kept;
    zBuffer(s, camera, params, into, [&](int x, int y, float z) {
      ++out.other_points;
      if (z_max(y, x) <= 0.f) {
        ++out.removed_unverified;
        return params.keep_unverified;
      }
      if (z < lo * z_min(y, x) || z > hi * z_max(y, x)) {
        ++out.removed_disagreeing;
        return false;
      }
      return true;
    });
  }
  compare(own, other_raw, out);
  out.depth = toReference(params.combine == AccumulationParams::Combine::kMajority
                              ? majorityOf(layers, params.tolerance)
                              : cv::Mat1f(cv::min(own, kept)));
  out.own = own_zero > 0.f;
  out.own_pixels = cv::countNonZero(out.own);
  out.pixels = cv::countNonZero(out.depth);
  return out;
}

std::vector<PosedSweep> loadPosedSweeps(const std::string& drive_dir, const std::string& target,
                                        const Calibration& calib,
                                        const AccumulationParams& params) {
  params.validate();
  const long center = static_cast<long>(frameIndex(target));
  const std::vector<OxtsSample> samples = readOxtsDrive(drive_dir);
  const std::vector<Eigen::Isometry3d> poses = posesRelativeToFirst(samples);
  std::map<long, size_t> by_index;
  for (size_t i = 0; i < samples.size(); ++i) by_index[frameIndex(samples[i].name)] = i;
  const Eigen::Isometry3d T_velo_imu = readImuToVelo(calibrationDirOf(drive_dir));
  const size_t name_width = target.size();
  auto poseOf = [&](long index, const std::string& name) {
    const auto it = by_index.find(index);
    if (it == by_index.end()) {
      throw std::runtime_error("KITTI: frame " + name + " of " + drive_dir + " has no oxts packet");
    }
    return poses[it->second];
  };
  const Eigen::Isometry3d world_from_target = poseOf(center, target);
  std::vector<PosedSweep> sweeps;
  for (long k = center - params.half_span; k <= center + params.half_span; ++k) {
    if (k < 0)
      throw std::runtime_error("KITTI: frame " + target + " has no sweep " + std::to_string(k) +
                               " before it");
    std::string name = std::to_string(k);
    name.insert(0, name_width > name.size() ? name_width - name.size() : 0, '0');
    const fs::path bin = fs::path(drive_dir) / "velodyne_points" / "data" / (name + ".bin");
    if (!fs::is_regular_file(bin)) {
      throw std::runtime_error("KITTI: the accumulated reference of frame " + target +
                               " needs sweep " + bin.string());
    }
    PosedSweep sweep;
    sweep.name = name;
    sweep.own = k == center;
    sweep.cloud = readVelodyneBin(bin.string());
    const Eigen::Isometry3d target_from_k = world_from_target.inverse() * poseOf(k, name);
    sweep.T_cam_lidar = calib.T_cam_velo * T_velo_imu * target_from_k * T_velo_imu.inverse();
    sweeps.push_back(std::move(sweep));
  }
  return sweeps;
}

AccumulatedDepth buildAccumulatedReference(const std::string& drive_dir, const std::string& target,
                                           const Calibration& calib,
                                           const AccumulationParams& params) {
  return accumulateDepth(loadPosedSweeps(drive_dir, target, calib, params), calib.camera, params);
}

}  // namespace kitti
}  // namespace lidar_stereo_fusion
