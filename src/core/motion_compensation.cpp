#include "lidar_stereo_fusion/core/motion_compensation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

namespace lidar_stereo_fusion {

namespace {

bool isRigid(const Eigen::Isometry3d& T) {
  if (!T.matrix().allFinite()) return false;
  const Eigen::Matrix3d R = T.linear();
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
         std::abs(R.determinant() - 1.0) < 1e-6;
}

Eigen::Isometry3d interpolate(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double s) {
  const Eigen::Quaterniond qa(a.linear()), qb(b.linear());
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = qa.slerp(s, qb).toRotationMatrix();
  out.translation() = (1.0 - s) * a.translation() + s * b.translation();
  return out;
}

}  // namespace

void SweepMotion::validate() const {
  if (times.empty()) throw std::invalid_argument("SweepMotion: no sample");
  if (times.size() != target_from_lidar.size()) {
    throw std::invalid_argument("SweepMotion: " + std::to_string(times.size()) + " times but " +
                                std::to_string(target_from_lidar.size()) + " transforms");
  }
  for (size_t i = 0; i < times.size(); ++i) {
    if (!std::isfinite(times[i])) {
      throw std::invalid_argument("SweepMotion: sample " + std::to_string(i) +
                                  "'s time is not finite");
    }
    if (i > 0 && !(times[i] > times[i - 1])) {
      throw std::invalid_argument("SweepMotion: sample times must increase (sample " +
                                  std::to_string(i) + ")");
    }
    if (!isRigid(target_from_lidar[i])) {
      throw std::invalid_argument("SweepMotion: sample " + std::to_string(i) +
                                  "'s transform is not finite or not rigid");
    }
  }
}

Eigen::Isometry3d SweepMotion::at(double t) const {
  if (t <= times.front()) return target_from_lidar.front();
  if (t >= times.back()) return target_from_lidar.back();
  const size_t i =
      static_cast<size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  const double s = (t - times[i - 1]) / (times[i] - times[i - 1]);
  return interpolate(target_from_lidar[i - 1], target_from_lidar[i], s);
}

std::vector<double> sampleTimes(double t_first, double t_last, int count) {
  if (count < 1) throw std::invalid_argument("sampleTimes: count must be >= 1");
  if (!(t_last >= t_first)) throw std::invalid_argument("sampleTimes: t_last < t_first");
  if (count == 1 || t_last == t_first) return {0.5 * (t_first + t_last)};
  std::vector<double> times(count);
  for (int i = 0; i < count; ++i) times[i] = t_first + (t_last - t_first) * i / (count - 1);
  return times;
}

std::pair<double, double> timeSpan(const LidarCloud& cloud) {
  if (cloud.empty()) return {0.0, 0.0};
  double lo = cloud.front().time, hi = lo;
  for (const LidarPoint& p : cloud) {
    lo = std::min(lo, static_cast<double>(p.time));
    hi = std::max(hi, static_cast<double>(p.time));
  }
  return {lo, hi};
}

SweepMotion constantVelocityMotion(const Eigen::Vector3d& velocity,
                                   const Eigen::Vector3d& angular_velocity, double target_time,
                                   const std::vector<double>& times) {
  SweepMotion motion;
  motion.times = times;
  for (const double t : times) {
    const double dt = t - target_time;
    const Eigen::Vector3d rotation = angular_velocity * dt;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    if (rotation.norm() > 0.0) {
      T.linear() = Eigen::AngleAxisd(rotation.norm(), rotation.normalized()).toRotationMatrix();
    }
    T.translation() = velocity * dt;
    motion.target_from_lidar.push_back(T);
  }
  return motion;
}

void compensateMotion(LidarCloud& cloud, const SweepMotion& motion) {
  motion.validate();
  // Per point, the rotation is interpolated by a normalised lerp of the neighbouring samples'
  // quaternions instead of at()'s slerp: between samples a few milliseconds apart the rotation is
  // below a degree, where the two differ by about theta^3 / 60 (3e-8 rad at 0.7 deg), and nlerp
  // needs no sine.
  const size_t n = motion.times.size();
  std::vector<Eigen::Quaterniond> q(n);
  for (size_t i = 0; i < n; ++i) {
    q[i] = Eigen::Quaterniond(motion.target_from_lidar[i].linear());
    if (i > 0 && q[i].dot(q[i - 1]) < 0.0) q[i].coeffs() *= -1.0;  // the short way round
  }
  for (LidarPoint& p : cloud) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    const double t = p.time;
    size_t hi = static_cast<size_t>(std::upper_bound(motion.times.begin(), motion.times.end(), t) -
                                    motion.times.begin());
    size_t lo = hi == 0 ? 0 : hi - 1;
    hi = std::min(hi, n - 1);
    const double s =
        hi == lo
            ? 0.0
            : std::clamp((t - motion.times[lo]) / (motion.times[hi] - motion.times[lo]), 0.0, 1.0);
    Eigen::Quaterniond r;
    r.coeffs() = (1.0 - s) * q[lo].coeffs() + s * q[hi].coeffs();
    r.normalize();
    const Eigen::Vector3d translation = (1.0 - s) * motion.target_from_lidar[lo].translation() +
                                        s * motion.target_from_lidar[hi].translation();
    const Eigen::Vector3d moved = r * Eigen::Vector3d(p.x, p.y, p.z) + translation;
    p.x = static_cast<float>(moved.x());
    p.y = static_cast<float>(moved.y());
    p.z = static_cast<float>(moved.z());
  }
}

int removePointsHiddenBeside(LidarCloud& cloud, const Eigen::Isometry3d& T_cam_lidar,
                             const StereoCamera& camera) {
  camera.validate();
  struct Projected {
    size_t index;
    double azimuth, u, z;
  };
  std::map<int, std::vector<Projected>> rings;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const LidarPoint& p = cloud[i];
    if (p.ring < 0 || !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    const Eigen::Vector3d c = T_cam_lidar * Eigen::Vector3d(p.x, p.y, p.z);
    if (!(c.z() > 0.1)) continue;
    const double u = camera.fx * c.x() / c.z() + camera.cx;
    if (u < -0.5 || u >= camera.width - 0.5) continue;
    rings[p.ring].push_back(
        {i, std::atan2(static_cast<double>(p.y), static_cast<double>(p.x)), u, c.z()});
  }
  std::vector<char> hidden(cloud.size(), 0);
  std::vector<double> cover(camera.width);
  for (auto& [ring, points] : rings) {
    std::sort(points.begin(), points.end(),
              [](const Projected& a, const Projected& b) { return a.azimuth > b.azimuth; });
    std::fill(cover.begin(), cover.end(), std::numeric_limits<double>::infinity());
    for (size_t k = 0; k + 1 < points.size(); ++k) {
      const Projected &a = points[k], &b = points[k + 1];
      const double far = std::max(a.z, b.z);
      if (std::abs(a.z - b.z) > std::max(0.3, 0.05 * far)) continue;  // not one surface
      const int first = std::max(0, static_cast<int>(std::ceil(std::min(a.u, b.u))));
      const int last = std::min(camera.width - 1, static_cast<int>(std::floor(std::max(a.u, b.u))));
      for (int col = first; col <= last; ++col) cover[col] = std::min(cover[col], far);
    }
    for (const Projected& p : points) {
      const int col = std::clamp(static_cast<int>(std::floor(p.u + 0.5)), 0, camera.width - 1);
      if (cover[col] < p.z - std::max(0.5, 0.1 * p.z)) hidden[p.index] = 1;
    }
  }
  size_t kept = 0;
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (!hidden[i]) cloud[kept++] = cloud[i];
  }
  const int removed = static_cast<int>(cloud.size() - kept);
  cloud.resize(kept);
  return removed;
}

}  // namespace lidar_stereo_fusion
