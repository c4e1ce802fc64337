// Spinning LiDAR simulation: beam tables and ray casting of one sweep.
#include "lidar_stereo_fusion/sim/lidar_model.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

#include "lidar_stereo_fusion/sim/random.h"

namespace lidar_stereo_fusion {
namespace sim {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

/// `count` values from `first` to `last` inclusive, evenly spaced, appended to `out`.
void appendLinear(std::vector<double>& out, double first, double last, int count) {
  for (int i = 0; i < count; ++i) {
    out.push_back(count == 1 ? first : first + (last - first) * i / (count - 1));
  }
}

/// When each firing happens, and where the LiDAR is then.
struct SweepClock {
  /// Static sweep: time = azimuth / 360 deg * period, one pose. Moving: the Velodyne's clockwise
  /// spin (moving_time), each firing cast from pose_at(time).
  bool moving = false;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  double front_time = 0.0;
  const std::function<Eigen::Isometry3d(double)>* pose_at = nullptr;
};

/// Clockwise seen from above: azimuth a in (-180, 180] deg is reached at front_time - a / 360 * T.
double movingTime(double azimuth_deg, double front_time, double period) {
  const double a = azimuth_deg > 180.0 ? azimuth_deg - 360.0 : azimuth_deg;
  return front_time - a / 360.0 * period;
}

/// The rays of one ring, in azimuth order.
void castRing(const Scene& scene, const LidarModel& model, const SweepClock& clock,
              const LidarNoise& noise, int ring, LidarCloud& points,
              std::vector<Eigen::Vector3d>& truth) {
  const double elevation = model.elevations_deg[ring] * kDegToRad;
  const int firings = static_cast<int>(std::lround(360.0 / model.azimuth_step_deg));
  for (int j = 0; j < firings; ++j) {
    const double azimuth_deg = (j + 0.5) * model.azimuth_step_deg;  // never exactly 0
    const double azimuth = azimuth_deg * kDegToRad;
    const double time = clock.moving ? movingTime(azimuth_deg, clock.front_time, model.sweep_period)
                                     : (j + 0.5) / firings * model.sweep_period;
    const Eigen::Isometry3d T_world_lidar = clock.moving ? (*clock.pose_at)(time) : clock.pose;
    const Eigen::Vector3d origin = T_world_lidar.translation();
    const Eigen::Vector3d dir_lidar(std::cos(elevation) * std::cos(azimuth),
                                    std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    const Eigen::Vector3d dir_world = T_world_lidar.linear() * dir_lidar;
    Hit hit;
    // A surface closer than min_range blocks the beam (no return), it is not looked through.
    if (!scene.intersect(origin, dir_world, 0.0, model.max_range, &hit)) continue;
    if (hit.t < model.min_range) continue;
    const uint64_t key =
        hashCombine(noise.seed, static_cast<uint64_t>(ring), static_cast<uint64_t>(j));
    if (noise.dropout_probability > 0.0 &&
        unitFromHash(hashCombine(key, 1)) < noise.dropout_probability) {
      continue;
    }
    double range = hit.t;
    if (noise.range_sigma_m > 0.0) {
      range += noise.range_sigma_m * normalFromHashes(hashCombine(key, 2), hashCombine(key, 3));
    }
    const double cos_incidence = std::abs(hit.normal.dot(dir_world));
    LidarPoint p;
    p.x = static_cast<float>(range * dir_lidar.x());
    p.y = static_cast<float>(range * dir_lidar.y());
    p.z = static_cast<float>(range * dir_lidar.z());
    p.intensity = static_cast<float>(std::clamp(
        scene.material(hit.material).lidar_reflectivity * std::max(cos_incidence, 0.1), 0.0, 1.0));
    p.ring = ring;
    p.time = static_cast<float>(time);
    points.push_back(p);
    truth.push_back(hit.point);
  }
}

}  // namespace

LidarModel LidarModel::hdl64() {
  LidarModel m;
  appendLinear(m.elevations_deg, 2.0, -8.33, 32);    // upper block, ~1/3 deg apart
  appendLinear(m.elevations_deg, -8.83, -24.8, 32);  // lower block, ~1/2 deg apart
  m.azimuth_step_deg = 0.09;
  return m;
}

LidarModel LidarModel::vls128() {
  LidarModel m;
  appendLinear(m.elevations_deg, 15.0, 4.2, 10);    // 1.2 deg apart
  appendLinear(m.elevations_deg, 3.4, 1.3, 8);      // 0.3 deg apart
  appendLinear(m.elevations_deg, 1.0, -7.69, 80);   // 0.11 deg apart around the horizon
  appendLinear(m.elevations_deg, -8.3, -25.0, 30);  // ~0.58 deg apart
  m.azimuth_step_deg = 0.2;
  m.max_range = 200.0;
  return m;
}

LidarModel LidarModel::forRings(int rings) {
  if (rings == 64) return hdl64();
  if (rings == 128) return vls128();
  throw std::invalid_argument(
      "sim::LidarModel: rings must be 64 (HDL-64E-like) or 128 "
      "(VLS-128-like), got " +
      std::to_string(rings));
}

void LidarModel::validate() const {
  if (elevations_deg.empty()) throw std::invalid_argument("sim::LidarModel: no beams");
  for (double e : elevations_deg) {
    if (!(std::abs(e) < 90.0)) {
      throw std::invalid_argument("sim::LidarModel: elevation must be in (-90, 90) deg");
    }
  }
  if (!(azimuth_step_deg > 0.0 && azimuth_step_deg <= 10.0)) {
    throw std::invalid_argument("sim::LidarModel: azimuth_step_deg must be in (0, 10]");
  }
  if (!(min_range >= 0.0 && max_range > min_range)) {
    throw std::invalid_argument("sim::LidarModel: need 0 <= min_range < max_range [m]");
  }
  if (!(sweep_period > 0.0)) throw std::invalid_argument("sim::LidarModel: sweep_period <= 0");
}

namespace {

SimulatedSweep castSweep(const Scene& scene, const LidarModel& model, const SweepClock& clock,
                         const LidarNoise& noise) {
  model.validate();
  if (!(noise.range_sigma_m >= 0.0) ||
      !(noise.dropout_probability >= 0.0 && noise.dropout_probability < 1.0)) {
    throw std::invalid_argument(
        "sim::simulateSweep: need range_sigma_m >= 0 and dropout_probability in [0, 1)");
  }
  const int rings = model.rings();
  std::vector<LidarCloud> ring_points(rings);
  std::vector<std::vector<Eigen::Vector3d>> ring_truth(rings);
#pragma omp parallel for schedule(dynamic)
  for (int r = 0; r < rings; ++r) {
    castRing(scene, model, clock, noise, r, ring_points[r], ring_truth[r]);
  }
  SimulatedSweep sweep;
  for (int r = 0; r < rings; ++r) {
    sweep.cloud.insert(sweep.cloud.end(), ring_points[r].begin(), ring_points[r].end());
    sweep.true_points.insert(sweep.true_points.end(), ring_truth[r].begin(), ring_truth[r].end());
  }
  return sweep;
}

}  // namespace

SimulatedSweep simulateSweep(const Scene& scene, const LidarModel& model,
                             const Eigen::Isometry3d& T_world_lidar, const LidarNoise& noise) {
  SweepClock clock;
  clock.pose = T_world_lidar;
  return castSweep(scene, model, clock, noise);
}

SimulatedSweep simulateMovingSweep(const Scene& scene, const LidarModel& model,
                                   const std::function<Eigen::Isometry3d(double)>& pose_at,
                                   double front_time, const LidarNoise& noise) {
  SweepClock clock;
  clock.moving = true;
  clock.front_time = front_time;
  clock.pose_at = &pose_at;
  return castSweep(scene, model, clock, noise);
}

}  // namespace sim
}  // namespace lidar_stereo_fusion
