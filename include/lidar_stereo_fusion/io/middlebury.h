// Middlebury 2003 stereo scenes (cones, teddy); the pseudo-LiDAR sampled from their ground truth is
// eval/pseudo_lidar.h. ROS-free.
#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace lidar_stereo_fusion {

/// One scene: im2 (left), im6 (right), disp2 (left ground truth).
struct MiddleburyScene {
  cv::Mat left, right;  ///< BGR CV_8UC3
  cv::Mat1f disparity;  ///< left ground-truth disparity [px] = PNG value / scale, 0 = unknown
};

/// Reads `dir`/im2.png, im6.png and disp2.png (quarter size: disparity_scale = 4). Throws
/// std::runtime_error naming the file when one is missing, unreadable, not 8-bit, or of another
/// size; std::invalid_argument when disparity_scale <= 0.
MiddleburyScene readMiddleburyScene(const std::string& dir, double disparity_scale = 4.0);

}  // namespace lidar_stereo_fusion
