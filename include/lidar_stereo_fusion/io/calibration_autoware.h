// Autoware camera-LiDAR calibration files (OpenCV FileStorage YAML). ROS-free.
//
// Direction: Autoware's CameraExtrinsicMat is the pose of the camera in the LiDAR frame, i.e. it
// maps camera coordinates into LiDAR coordinates (T_lidar_cam). Projecting a LiDAR point uses its
// inverse: p_cam = CameraExtrinsicMat^-1 * p_lidar.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

namespace lidar_stereo_fusion {

struct AutowareCalibration {
  Eigen::Isometry3d T_lidar_cam;   ///< CameraExtrinsicMat (camera pose in the LiDAR frame)
  cv::Matx33d camera_matrix;       ///< CameraMat
  cv::Mat dist_coeffs;             ///< DistCoeff (1xN)
  cv::Size image_size;             ///< ImageSize
  double reprojection_error = -1;  ///< ReprojectionError (-1 when absent) [px]
  std::string dist_model;          ///< DistModel ("plumb_bob" when absent)
  struct Pair { double u, v, x, y, z; };
  std::vector<Pair> calib_data;    ///< CalibData clicked pairs (pixel u, v; LiDAR point x, y, z)
};

/// Reads the file; unknown keys are ignored. Throws std::runtime_error naming the missing key.
AutowareCalibration readAutowareCalibration(const std::string& path);

/// Mean reprojection error [px] of the CalibData pairs with the file's extrinsic and intrinsics.
double meanReprojectionError(const AutowareCalibration& calib);

}  // namespace lidar_stereo_fusion
