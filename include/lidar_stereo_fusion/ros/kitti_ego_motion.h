// The ego-motion of a KITTI raw drive as TF messages (kitti_to_bag): the static IMU -> Velodyne
// transform of calib_imu_to_velo.txt and the oxts poses of the drive. Same TF direction as
// calibration_msgs.h: header.frame_id = parent, child_frame_id = child, transform = T_parent_child.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <geometry_msgs/TransformStamped.h>
#include <ros/time.h>
#include <Eigen/Geometry>

#include "lidar_stereo_fusion/io/kitti_oxts.h"

namespace lidar_stereo_fusion {

/// Static transform imu_frame -> velodyne_frame: the Velodyne's pose in the IMU frame,
/// T_velo_imu^-1 (T_velo_imu from kitti::readImuToVelo maps IMU into Velodyne coordinates).
geometry_msgs::TransformStamped kittiImuToVelodyne(const Eigen::Isometry3d& T_velo_imu,
                                                   const std::string& imu_frame,
                                                   const std::string& velodyne_frame,
                                                   const ros::Time& stamp);

/// fixed_frame -> imu_frame at each sample's stamp: the IMU pose relative to the first sample's
/// (kitti::posesRelativeToFirst), so the fixed frame is the first packet's IMU frame.
std::vector<geometry_msgs::TransformStamped> kittiEgoMotionTf(
    const std::vector<kitti::OxtsSample>& samples, const std::string& fixed_frame,
    const std::string& imu_frame);

/// The samples of `all` (sorted by stamp) from the last one at or before `first` [s] to the first
/// one at or after `last` [s]: what TF needs to interpolate over [first, last].
std::vector<kitti::OxtsSample> samplesBracketing(const std::vector<kitti::OxtsSample>& all,
                                                 double first, double last);

/// A drive's ego-motion.
struct KittiEgoMotion {
  std::optional<Eigen::Isometry3d> T_velo_imu;  ///< empty without calib_imu_to_velo.txt
  std::vector<kitti::OxtsSample> samples;       ///< bracketing the frames; empty: no /tf
};

/// Reads calib_imu_to_velo.txt from `calib_dir` and the oxts samples of `drive_dir` bracketing
/// [first, last] [s]. Writes a line to `notes` for what is left out and why: no calibration (then
/// nothing), `restamped` frames (no samples: their stamps are not the drive's), no oxts/data, and
/// packets without a stamp (named). Throws std::runtime_error on malformed files.
KittiEgoMotion readKittiEgoMotion(const std::string& calib_dir, const std::string& drive_dir,
                                  bool restamped, double first, double last, std::ostream& notes);

}  // namespace lidar_stereo_fusion
