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
  struct Pair {
    double u, v, x, y, z;
  };
  std::vector<Pair> calib_data;  ///< CalibData clicked pairs (pixel u, v; LiDAR point x, y, z)
};

/// Reads the file; unknown keys are ignored. Throws std::runtime_error naming the missing key.
AutowareCalibration readAutowareCalibration(const std::string& path);

/// LiDAR -> camera optical frame: the inverse of CameraExtrinsicMat.
Eigen::Isometry3d cameraFromLidar(const AutowareCalibration& calib);

/// Projects a point of the camera optical frame [m] (z > 0) to pixels with CameraMat and DistCoeff
/// (plumb_bob k1 k2 p1 p2 [k3], or rational_polynomial k1 k2 p1 p2 k3 k4 k5 k6), as
/// cv::projectPoints does with a zero pose. Throws std::invalid_argument when z <= 0 or the
/// distortion model / coefficients are unsupported.
cv::Point2d projectToImage(const AutowareCalibration& calib, const Eigen::Vector3d& p_cam);

/// Mean reprojection error [px] of the CalibData pairs with the file's extrinsic and intrinsics
/// (p_cam = CameraExtrinsicMat^-1 p_lidar, then projectToImage). A pair behind the camera makes
/// the error infinite.
/// Throws std::invalid_argument when there are no pairs or the distortion model is unsupported.
double meanReprojectionError(const AutowareCalibration& calib);

/// The same with an explicit LiDAR -> camera transform (e.g. to compare directions).
double meanReprojectionError(const AutowareCalibration& calib,
                             const Eigen::Isometry3d& T_cam_lidar);

}  // namespace lidar_stereo_fusion
