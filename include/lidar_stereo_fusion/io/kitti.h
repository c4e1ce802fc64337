// Reading and writing the KITTI raw layout and the KITTI depth-completion PNG format. ROS-free.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {
namespace kitti {

/// Calibration of one KITTI raw drive date (calib_cam_to_cam.txt + calib_velo_to_cam.txt).
struct Calibration {
  StereoCamera camera;                 ///< rectified cam 2 (left colour) with baseline to cam 3
  Eigen::Isometry3d T_cam_velo;        ///< Velodyne -> rectified cam 2 optical frame
  Eigen::Matrix<double, 3, 4> P2, P3;  ///< P_rect_02, P_rect_03
};

/// Reads `dir`/calib_cam_to_cam.txt and `dir`/calib_velo_to_cam.txt. Throws std::runtime_error
/// naming the file and the missing/malformed key.
Calibration readCalibration(const std::string& dir);

/// Reads a .bin sweep (float32 x, y, z, reflectance). Throws std::runtime_error when the file is
/// unreadable or its size is not a multiple of 16 bytes. Rings are left at -1.
LidarCloud readVelodyneBin(const std::string& path);
/// Writes a cloud as a .bin sweep.
void writeVelodyneBin(const std::string& path, const LidarCloud& cloud);

/// Reads a KITTI depth PNG (uint16, metres * 256, 0 = none) into metres. Throws on failure.
cv::Mat1f readDepthPng(const std::string& path);
/// Writes depth [m] (0 / NaN / inf = none) as a KITTI depth PNG. Throws on failure.
void writeDepthPng(const std::string& path, const cv::Mat1f& depth_m);

/// One frame of a drive (paths; files are read on demand).
struct Frame {
  std::string name;        ///< e.g. "0000000005"
  std::string left_image, right_image, velodyne;
};
/// Lists frames of `drive_dir` that have image_02, image_03 and a velodyne .bin, sorted by name.
std::vector<Frame> listFrames(const std::string& drive_dir);

/// Reads timestamps.txt lines ("2011-09-26 13:02:25.964389445") as seconds since the epoch (UTC).
std::vector<double> readTimestamps(const std::string& path);

}  // namespace kitti
}  // namespace lidar_stereo_fusion
