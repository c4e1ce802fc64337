// Ego-motion compensation of a LiDAR sweep ("deskewing"): every point is moved from the instant
// it was measured to one target instant (the left image's stamp), so that a sweep taken while the
// rig moves, and a sweep taken at another instant than the images, project where the images saw
// the scene. Not in the paper (its KITTI sweeps are projected as they come); METHOD.md's stage 1
// takes the compensated cloud.
//
// Conventions: times are seconds relative to one base (the cloud's stamp: LidarPoint::time is the
// offset of the point's measurement from it, any sign). The motion is sampled at a few instants
// over the sweep and interpolated between them (translation linearly, rotation by slerp), so that
// callers look a transform up a bounded number of times per sweep, never per point.
#pragma once

#include <vector>

#include <Eigen/Geometry>

#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {

/// The LiDAR's motion over a sweep: at each sample time, the transform from the LiDAR frame at
/// that instant to the LiDAR frame at the target instant.
struct SweepMotion {
  std::vector<double> times;  ///< [s] relative to the cloud's stamp, strictly increasing
  std::vector<Eigen::Isometry3d> target_from_lidar;  ///< one per time: LiDAR(t) -> LiDAR(target)

  /// Throws std::invalid_argument when the sizes differ, there is no sample, a time is not finite
  /// or not increasing, or a transform is not finite or not rigid.
  void validate() const;
  /// The transform at time t [s]: interpolated between the neighbouring samples (translation
  /// linearly, rotation by slerp), held constant before the first and after the last sample.
  Eigen::Isometry3d at(double t) const;
};

/// `count` instants [s] evenly spaced over [t_first, t_last] (both included; one instant, the
/// mid-point, for count 1). Throws std::invalid_argument for count < 1 or t_last < t_first.
std::vector<double> sampleTimes(double t_first, double t_last, int count);

/// The earliest and latest LiDAR point times of `cloud` [s]; {0, 0} for an empty cloud.
std::pair<double, double> timeSpan(const LidarCloud& cloud);

/// Constant-velocity motion: a rig moving with linear velocity `velocity` [m/s] and angular
/// velocity `angular_velocity` [rad/s], both in the LiDAR frame, sampled at `times`; the target
/// instant is `target_time` [s] (same base). The LiDAR at time t is displaced from the LiDAR at
/// the target by the rotation exp(w (t - target)) and the translation v (t - target).
SweepMotion constantVelocityMotion(const Eigen::Vector3d& velocity,
                                   const Eigen::Vector3d& angular_velocity, double target_time,
                                   const std::vector<double>& times);

/// Moves every point of `cloud` (LiDAR frame, [m]) from its time to the target instant of
/// `motion`: p' = motion.at(p.time) * p, the rotation interpolated by normalised lerp: it differs
/// from at()'s slerp by about theta^3 / 60 for a rotation theta [rad] between neighbouring samples
/// (3e-8 rad at 0.7 deg, a car's yaw over 25 ms in a tight bend). Non-finite
/// points stay as they are (the projection skips them). Throws std::invalid_argument if
/// motion.validate() fails.
void compensateMotion(LidarCloud& cloud, const SweepMotion& motion);

/// A compensated sweep was measured from up to a metre ahead of (or behind) the camera: beside a
/// near object it holds background the camera cannot see, which lands inside the object's
/// silhouette in the image. Algorithm 1 removes only points hidden by a foreground above and below
/// them; these are hidden beside. Per ring (points with ring < 0 are left alone), the segments
/// between consecutive points in azimuth order that lie on one surface (depths within 5 %, at
/// least 0.3 m) cover image columns at their farther depth; a point whose column is covered by a
/// segment nearer than its own depth by more than 10 % (at least 0.5 m) is removed. Returns the
/// number removed. Throws std::invalid_argument for an invalid camera.
int removePointsHiddenBeside(LidarCloud& cloud, const Eigen::Isometry3d& T_cam_lidar,
                             const StereoCamera& camera);

}  // namespace lidar_stereo_fusion
