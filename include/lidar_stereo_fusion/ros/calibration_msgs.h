// ROS messages (static transforms, camera infos) built from the ROS-free calibration readers.
//
// TF direction used throughout (the tf2 convention): a TransformStamped with
// header.frame_id = parent and child_frame_id = child carries the pose of the child frame in the
// parent frame, T_parent_child, which maps child coordinates into parent coordinates.
// tf2 lookupTransform(target, source) returns T_target_source, so looking up
// (target = camera frame, source = LiDAR frame) on a tree with parent = LiDAR, child = camera
// returns T_cam_lidar = T_lidar_cam^-1: the transform that moves LiDAR points into the camera
// frame. Every calibration publisher here uses parent = LiDAR frame, child = camera frame.
#pragma once

#include <string>

#include <geometry_msgs/TransformStamped.h>
#include <ros/time.h>
#include <sensor_msgs/CameraInfo.h>
#include <Eigen/Geometry>

#include "lidar_stereo_fusion/core/types.h"
#include "lidar_stereo_fusion/io/calibration_autoware.h"
#include "lidar_stereo_fusion/io/kitti.h"

namespace lidar_stereo_fusion {

/// Largest |R R^T - I| entry accepted as a rotation by the message builders below.
constexpr double kRotationTolerance = 1e-4;

/// Transform message parent -> child carrying `T_parent_child` (pose of `child` in `parent`;
/// maps child coordinates into parent coordinates; translation in metres). Throws
/// std::invalid_argument when the frames are empty or equal, when the linear part is not a
/// rotation (orthonormal within kRotationTolerance, determinant +1) or when a value is not finite.
geometry_msgs::TransformStamped transformMsg(const Eigen::Isometry3d& T_parent_child,
                                             const std::string& parent, const std::string& child,
                                             const ros::Time& stamp);

/// Static transform lidar_frame -> camera_frame of an Autoware calibration: parent = LiDAR frame,
/// transform = CameraExtrinsicMat = T_lidar_cam (camera pose in the LiDAR frame). A tf2 lookup
/// (target = camera_frame, source = lidar_frame) then maps LiDAR points into the camera frame.
geometry_msgs::TransformStamped autowareLidarToCamera(const AutowareCalibration& calib,
                                                      const std::string& lidar_frame,
                                                      const std::string& camera_frame,
                                                      const ros::Time& stamp);

/// Static transform velodyne_frame -> camera_frame of a KITTI calibration: parent = Velodyne
/// frame, child = rectified cam-2 optical frame, transform = T_cam_velo^-1 (camera pose in the
/// Velodyne frame). A tf2 lookup (target = camera_frame, source = velodyne_frame) returns
/// T_cam_velo, so transforming a Velodyne point through TF gives T_cam_velo * p.
geometry_msgs::TransformStamped kittiVelodyneToCamera(const kitti::Calibration& calib,
                                                      const std::string& velodyne_frame,
                                                      const std::string& camera_frame,
                                                      const ros::Time& stamp);

/// Static transform left_frame -> right_frame of a rectified stereo pair: parent = left optical
/// frame, child = right optical frame, translation (+baseline, 0, 0) m, identity rotation (the
/// right camera sits baseline metres along the left camera's +x axis).
geometry_msgs::TransformStamped stereoLeftToRight(const StereoCamera& camera,
                                                  const std::string& left_frame,
                                                  const std::string& right_frame,
                                                  const ros::Time& stamp);

/// Camera info of an Autoware calibration's (unrectified) camera: K = CameraMat,
/// D = DistCoeff, distortion_model = DistModel, width/height = ImageSize, R = I, P = [K | 0]
/// (all in pixels). header.frame_id = `frame`, stamp left zero.
sensor_msgs::CameraInfo autowareCameraInfo(const AutowareCalibration& calib,
                                           const std::string& frame);

/// Camera info of one view of a rectified stereo pair (no distortion, R = I):
/// K = [fx 0 cx; 0 fy cy; 0 0 1], P = [fx 0 cx Tx; 0 fy cy 0; 0 0 1 0] with Tx = 0 for the left
/// view and Tx = -fx * baseline [px * m] for the right one (the image_geometry convention).
/// header.frame_id = `frame`, stamp left zero. Calls camera.validate().
sensor_msgs::CameraInfo rectifiedCameraInfo(const StereoCamera& camera, const std::string& frame,
                                            bool right_view);

}  // namespace lidar_stereo_fusion
