// The core pipeline's depth for one KITTI frame, for test_kitti_bag, in its own translation unit so
// that the ROS test source does not pull in the core pipeline.
#pragma once

#include <string>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/io/kitti.h"

namespace lidar_stereo_fusion {
namespace test {

/// Runs the core pipeline with the parameters of `params_yaml` on `frame` (files read with
/// kitti::loadFrame), the rectified camera of `calib` and LiDAR -> left optical frame
/// `T_cam_lidar`; returns the depth [m] (0 = none).
cv::Mat1f expectedDepth(const std::string& params_yaml, const kitti::Frame& frame,
                        const kitti::Calibration& calib, const Eigen::Isometry3d& T_cam_lidar);

}  // namespace test
}  // namespace lidar_stereo_fusion
