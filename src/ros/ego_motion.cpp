#include "lidar_stereo_fusion/ros/ego_motion.h"

#include <tf2/exceptions.h>
#include <tf2_eigen/tf2_eigen.h>

namespace lidar_stereo_fusion {

SweepMotion sweepMotionFromTf(const tf2::BufferCore& tf, const std::string& lidar_frame,
                              const std::string& fixed_frame, const ros::Time& sweep_stamp,
                              const ros::Time& target_stamp, const std::vector<double>& times) {
  SweepMotion motion;
  motion.times = times;
  for (const double t : times) {
    const ros::Time at = sweep_stamp + ros::Duration(t);
    try {
      motion.target_from_lidar.push_back(tf2::transformToEigen(
          tf.lookupTransform(lidar_frame, target_stamp, lidar_frame, at, fixed_frame)));
    } catch (const tf2::TransformException& e) {
      throw tf2::TransformException("no ego-motion of '" + lidar_frame + "' in '" + fixed_frame +
                                    "' between " + std::to_string(at.toSec()) + " (sweep) and " +
                                    std::to_string(target_stamp.toSec()) + " (image): " + e.what());
    }
  }
  return motion;
}

void compensateSweep(const tf2::BufferCore& tf, const std::string& lidar_frame,
                     const std::string& fixed_frame, const ros::Time& sweep_stamp,
                     const ros::Time& image_stamp, const std::vector<double>& times,
                     const Eigen::Isometry3d& T_cam_lidar, const StereoCamera& camera,
                     LidarCloud& cloud) {
  const SweepMotion motion =
      sweepMotionFromTf(tf, lidar_frame, fixed_frame, sweep_stamp, image_stamp, times);
  compensateMotion(cloud, motion);
  // Measured from elsewhere than the camera: what it cannot see beside near objects goes.
  removePointsHiddenBeside(cloud, T_cam_lidar, camera);
}

std::vector<double> motionSampleTimes(const LidarCloud& cloud, bool has_time, int samples) {
  if (!has_time || cloud.empty()) return {0.0};
  const auto [first, last] = timeSpan(cloud);
  return sampleTimes(first, last, samples);
}

}  // namespace lidar_stereo_fusion
