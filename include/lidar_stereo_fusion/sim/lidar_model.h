// A simulated spinning multi-beam LiDAR (HDL-64E-like or VLS-128-like) cast into a sim::Scene.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Geometry>

#include "lidar_stereo_fusion/core/types.h"
#include "lidar_stereo_fusion/sim/scene.h"

namespace lidar_stereo_fusion {
namespace sim {

/// Beam layout and timing. All beams share one origin (the LiDAR frame: x forward, y left, z up).
struct LidarModel {
  /// Elevation of each laser [deg], ring 0 = the highest beam (the order KITTI stores HDL-64E
  /// lasers in its .bin sweeps, so recoverRingsBySweepOrder gives back the same ring indices).
  std::vector<double> elevations_deg;
  double azimuth_step_deg = 0.09;  ///< angle between consecutive firings of one laser [deg]
  double min_range = 0.9;          ///< returns closer than this are lost [m]
  double max_range = 120.0;        ///< returns farther than this are lost [m]
  double sweep_period = 0.1;       ///< one revolution [s]

  int rings() const { return static_cast<int>(elevations_deg.size()); }
  /// HDL-64E-like: 32 upper lasers +2.0 .. -8.33 deg, 32 lower lasers -8.83 .. -24.8 deg, 0.09 deg.
  static LidarModel hdl64();
  /// VLS-128-like: +15 .. -25 deg, 0.11 deg spacing around the horizon, sparser above and below,
  /// 0.2 deg azimuth step.
  static LidarModel vls128();
  /// hdl64() for 64, vls128() for 128; throws std::invalid_argument otherwise.
  static LidarModel forRings(int rings);
  /// Throws std::invalid_argument naming the first impossible value.
  void validate() const;
};

/// Measurement imperfections (all off by default: exact points).
struct LidarNoise {
  double range_sigma_m = 0.0;        ///< Gaussian noise along the beam [m]
  double dropout_probability = 0.0;  ///< probability that a return is lost, in [0, 1)
  uint64_t seed = 0;
};

/// A sweep and, per point, the exact surface point its beam hit.
struct SimulatedSweep {
  LidarCloud cloud;  ///< LiDAR frame [m]; ring, intensity in [0, 1], time in [0, sweep_period) [s]
  std::vector<Eigen::Vector3d> true_points;  ///< noise-free hit points, street frame [m]
};

/// Casts every beam of `model` from the pose `T_world_lidar` (LiDAR frame -> street frame).
/// Points are stored ring by ring from ring 0; within a ring the azimuth atan2(y, x) rises from
/// just above 0 (straight ahead) through +-180 deg to just below 0, as in KITTI .bin files. Beams
/// that hit nothing within [min_range, max_range] give no point. The time of a point is
/// azimuth / 360 deg * sweep_period (the scene is static during the sweep).
SimulatedSweep simulateSweep(const Scene& scene, const LidarModel& model,
                             const Eigen::Isometry3d& T_world_lidar, const LidarNoise& noise);

/// A sweep taken while the LiDAR moves, spinning clockwise seen from above as a Velodyne does: the
/// firing at azimuth a (atan2(y, x) in (-180, 180] deg) happens at time
/// t(a) = front_time - a / 360 deg * sweep_period [s] (straight ahead at front_time, the rear half
/// a period before and after) and is cast from `pose_at(t)` (LiDAR frame -> street frame). Points
/// are stored as by simulateSweep; a point's time is its t(a) [s], on the caller's time base.
SimulatedSweep simulateMovingSweep(const Scene& scene, const LidarModel& model,
                                   const std::function<Eigen::Isometry3d(double)>& pose_at,
                                   double front_time, const LidarNoise& noise);

}  // namespace sim
}  // namespace lidar_stereo_fusion
