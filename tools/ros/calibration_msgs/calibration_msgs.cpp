// ROS messages (static transforms, camera infos) built from the ROS-free calibration readers.
#include "lidar_stereo_fusion/ros/calibration_msgs.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace lidar_stereo_fusion {
namespace {

void requireRotation(const Eigen::Matrix3d& r, const std::string& what) {
  const double orthogonality =
      (r * r.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!r.allFinite() || !(orthogonality <= kRotationTolerance) ||
      !(std::abs(r.determinant() - 1.0) <= kRotationTolerance)) {
    std::ostringstream msg;
    msg << what
        << ": the rotation part is not a rotation matrix (max |R R^T - I| = " << orthogonality
        << ", det = " << r.determinant() << ")";
    throw std::invalid_argument(msg.str());
  }
}

}  // namespace

geometry_msgs::TransformStamped transformMsg(const Eigen::Isometry3d& T_parent_child,
                                             const std::string& parent, const std::string& child,
                                             const ros::Time& stamp) {
  const std::string what = "transform " + parent + " -> " + child;
  if (parent.empty() || child.empty()) {
    throw std::invalid_argument(what + ": frame ids must not be empty");
  }
  if (parent == child) throw std::invalid_argument(what + ": parent and child are the same frame");
  requireRotation(T_parent_child.linear(), what);
  const Eigen::Vector3d t = T_parent_child.translation();
  if (!t.allFinite()) throw std::invalid_argument(what + ": translation is not finite");

  geometry_msgs::TransformStamped msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = parent;
  msg.child_frame_id = child;
  msg.transform.translation.x = t.x();
  msg.transform.translation.y = t.y();
  msg.transform.translation.z = t.z();
  // Calibration files store rotations to ~1e-8; the quaternion of the (nearly orthonormal)
  // matrix, normalised, is the nearest rotation to that precision.
  const Eigen::Quaterniond q = Eigen::Quaterniond(T_parent_child.linear()).normalized();
  msg.transform.rotation.x = q.x();
  msg.transform.rotation.y = q.y();
  msg.transform.rotation.z = q.z();
  msg.transform.rotation.w = q.w();
  return msg;
}

geometry_msgs::TransformStamped autowareLidarToCamera(const AutowareCalibration& calib,
                                                      const std::string& lidar_frame,
                                                      const std::string& camera_frame,
                                                      const ros::Time& stamp) {
  // CameraExtrinsicMat is already the camera pose in the LiDAR frame (= T_parent_child).
  return transformMsg(calib.T_lidar_cam, lidar_frame, camera_frame, stamp);
}

geometry_msgs::TransformStamped kittiVelodyneToCamera(const kitti::Calibration& calib,
                                                      const std::string& velodyne_frame,
                                                      const std::string& camera_frame,
                                                      const ros::Time& stamp) {
  // T_cam_velo maps Velodyne points into the camera; the camera pose in the Velodyne frame
  // (T_parent_child with parent = velodyne) is its inverse.
  return transformMsg(calib.T_cam_velo.inverse(), velodyne_frame, camera_frame, stamp);
}

geometry_msgs::TransformStamped stereoLeftToRight(const StereoCamera& camera,
                                                  const std::string& left_frame,
                                                  const std::string& right_frame,
                                                  const ros::Time& stamp) {
  if (!(camera.baseline > 0) || !std::isfinite(camera.baseline)) {
    throw std::invalid_argument("transform " + left_frame + " -> " + right_frame +
                                ": baseline must be a finite positive number of metres");
  }
  Eigen::Isometry3d T_left_right = Eigen::Isometry3d::Identity();
  T_left_right.translation() = Eigen::Vector3d(camera.baseline, 0.0, 0.0);
  return transformMsg(T_left_right, left_frame, right_frame, stamp);
}

sensor_msgs::CameraInfo autowareCameraInfo(const AutowareCalibration& calib,
                                           const std::string& frame) {
  if (calib.image_size.width <= 0 || calib.image_size.height <= 0) {
    throw std::invalid_argument("Autoware camera info: ImageSize must be positive");
  }
  sensor_msgs::CameraInfo info;
  info.header.frame_id = frame;
  info.width = static_cast<uint32_t>(calib.image_size.width);
  info.height = static_cast<uint32_t>(calib.image_size.height);
  info.distortion_model = calib.dist_model.empty() ? "plumb_bob" : calib.dist_model;
  cv::Mat1d dist;
  if (!calib.dist_coeffs.empty()) calib.dist_coeffs.convertTo(dist, CV_64F);
  info.D.assign(dist.begin(), dist.end());
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      info.K[3 * r + c] = calib.camera_matrix(r, c);
      info.P[4 * r + c] = calib.camera_matrix(r, c);
    }
    info.R[4 * r] = 1.0;  // R[0], R[4], R[8]: identity
  }
  return info;
}

sensor_msgs::CameraInfo rectifiedCameraInfo(const StereoCamera& camera, const std::string& frame,
                                            bool right_view) {
  camera.validate();
  sensor_msgs::CameraInfo info;
  info.header.frame_id = frame;
  info.width = static_cast<uint32_t>(camera.width);
  info.height = static_cast<uint32_t>(camera.height);
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);  // rectified images: no distortion left
  info.K = {camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0};
  info.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  const double tx = right_view ? -camera.fx * camera.baseline : 0.0;
  info.P = {camera.fx, 0.0, camera.cx, tx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  return info;
}

}  // namespace lidar_stereo_fusion
