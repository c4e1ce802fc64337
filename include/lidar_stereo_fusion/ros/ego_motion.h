// The rig's motion over a sweep from TF (~fixed_frame): a bounded number of lookups per sweep,
// interpolated per point by the core (core/motion_compensation.h). Used by the nodelet and by
// offline tools that hold a tf2::BufferCore filled from a bag.
#pragma once

#include <string>
#include <vector>

#include <ros/time.h>
#include <tf2/buffer_core.h>

#include "lidar_stereo_fusion/core/motion_compensation.h"

namespace lidar_stereo_fusion {

/// For each time t [s] of `times` (relative to `sweep_stamp`), the transform from the LiDAR frame
/// at sweep_stamp + t to the LiDAR frame at `target_stamp` (the left image's stamp), through
/// `fixed_frame` (the frame in which the world stands still, e.g. odom or map). Throws
/// tf2::TransformException when a lookup fails (missing frame, stale or future data); its what()
/// names the frames and the stamp that failed.
SweepMotion sweepMotionFromTf(const tf2::BufferCore& tf, const std::string& lidar_frame,
                              const std::string& fixed_frame, const ros::Time& sweep_stamp,
                              const ros::Time& target_stamp, const std::vector<double>& times);

/// The whole compensation, as the nodelet and bag_runner do it: moves `cloud` (LiDAR frame) from
/// its points' times to `image_stamp` with sweepMotionFromTf at `times`, then drops what the camera
/// cannot see beside near objects (removePointsHiddenBeside with `T_cam_lidar`, `camera`). Throws
/// tf2::TransformException as sweepMotionFromTf, before the cloud is changed.
void compensateSweep(const tf2::BufferCore& tf, const std::string& lidar_frame,
                     const std::string& fixed_frame, const ros::Time& sweep_stamp,
                     const ros::Time& image_stamp, const std::vector<double>& times,
                     const Eigen::Isometry3d& T_cam_lidar, const StereoCamera& camera,
                     LidarCloud& cloud);

/// The stamp to take the LiDAR -> camera extrinsics at: the sweep's, or the image's when the sweep
/// is moved there (`fixed_frame` set).
inline ros::Time extrinsicsStamp(const std::string& fixed_frame, const ros::Time& sweep_stamp,
                                 const ros::Time& image_stamp) {
  return fixed_frame.empty() ? sweep_stamp : image_stamp;
}

/// The instants a sweep's motion is sampled at: `samples` instants evenly over the span of the
/// cloud's point times, or the stamp alone (t = 0) when the points carry no time (the whole sweep
/// then moves from its stamp to the image's: the time offset alone).
std::vector<double> motionSampleTimes(const LidarCloud& cloud, bool has_time, int samples);

}  // namespace lidar_stereo_fusion
