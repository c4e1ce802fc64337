// Node autoware_calibration_publisher: publishes an Autoware camera-LiDAR calibration as the static
// transform lidar_frame -> camera_frame and, optionally, the camera's latched camera_info.
//
// Parameters (private):
//   ~calibration_file     (string, required) Autoware calibrator YAML (CameraExtrinsicMat, ...)
//   ~lidar_frame          (string, "velodyne") parent frame of the transform
//   ~camera_frame         (string, "left_camera_optical_frame") child frame (optical: x right,
//                         y down, z forward)
//   ~publish_camera_info  (bool, false) also publish `camera_info` (latched) from CameraMat,
//                         DistCoeff, DistModel and ImageSize
// Publications: /tf_static (tf2_msgs/TFMessage), camera_info (sensor_msgs/CameraInfo, latched).
//
// The transform carries CameraExtrinsicMat, the camera pose in the LiDAR frame (T_lidar_cam), so
// a tf2 lookup (target = camera_frame, source = lidar_frame) maps LiDAR points into the camera.
// Exits with status 1 and a message naming the file and the problem when the file is unusable.
#include <cmath>
#include <exception>
#include <string>

#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "lidar_stereo_fusion/io/calibration_autoware.h"
#include "lidar_stereo_fusion/ros/calibration_msgs.h"

namespace {

using lidar_stereo_fusion::AutowareCalibration;

/// Warns when the file's own CalibData pairs do not reproject with the extrinsic as read: that
/// happens when a tool wrote the inverse transform (LiDAR -> camera) into CameraExtrinsicMat.
void checkReprojection(const AutowareCalibration& calib, const std::string& path) {
  if (calib.calib_data.empty()) return;
  const double error = lidar_stereo_fusion::meanReprojectionError(calib);
  if (calib.reprojection_error >= 0 && !(error <= 2.0 * calib.reprojection_error + 1.0)) {
    ROS_WARN(
        "%s: CalibData reprojects with a mean error of %.2f px, the file states %.2f px; "
        "is CameraExtrinsicMat really the camera pose in the LiDAR frame?",
        path.c_str(), error, calib.reprojection_error);
  } else {
    ROS_INFO("%s: CalibData mean reprojection error %.3f px (file states %.3f px)", path.c_str(),
             error, calib.reprojection_error);
  }
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "autoware_calibration_publisher");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  const std::string path = pnh.param<std::string>("calibration_file", "");
  const std::string lidar_frame = pnh.param<std::string>("lidar_frame", "velodyne");
  const std::string camera_frame =
      pnh.param<std::string>("camera_frame", "left_camera_optical_frame");
  const bool publish_camera_info = pnh.param("publish_camera_info", false);
  if (path.empty()) {
    ROS_FATAL("parameter %s is not set: give the Autoware calibration YAML to publish",
              pnh.resolveName("calibration_file").c_str());
    return 1;
  }

  AutowareCalibration calib;
  geometry_msgs::TransformStamped transform;
  sensor_msgs::CameraInfo info;
  try {
    calib = lidar_stereo_fusion::readAutowareCalibration(path);
    transform = lidar_stereo_fusion::autowareLidarToCamera(calib, lidar_frame, camera_frame,
                                                           ros::Time::now());
    if (publish_camera_info) info = lidar_stereo_fusion::autowareCameraInfo(calib, camera_frame);
  } catch (const std::exception& e) {
    ROS_FATAL("cannot publish the Autoware calibration %s: %s", path.c_str(), e.what());
    return 1;
  }
  checkReprojection(calib, path);

  tf2_ros::StaticTransformBroadcaster broadcaster;
  broadcaster.sendTransform(transform);
  const auto& t = transform.transform.translation;
  ROS_INFO("static transform %s -> %s (camera pose in the LiDAR frame): t = [%.4f %.4f %.4f] m",
           lidar_frame.c_str(), camera_frame.c_str(), t.x, t.y, t.z);

  ros::Publisher info_pub;
  if (publish_camera_info) {
    info_pub = nh.advertise<sensor_msgs::CameraInfo>("camera_info", 1, /*latch=*/true);
    info.header.stamp = ros::Time::now();
    info_pub.publish(info);
  }
  ros::spin();
  return 0;
}
