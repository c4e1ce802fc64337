// Node kitti_calibration_publisher: publishes a KITTI raw calibration (calib_cam_to_cam.txt +
// calib_velo_to_cam.txt) as static transforms.
//
// Parameters (private):
//   ~calib_dir           (string, required) folder with the two calibration files (a drive date)
//   ~velodyne_frame      (string, "velodyne") parent frame
//   ~camera_frame        (string, "left_camera_optical_frame") rectified cam 2 (left colour)
//   ~right_camera_frame  (string, "right_camera_optical_frame") rectified cam 3; "" = not published
// Publications: /tf_static (tf2_msgs/TFMessage).
//
// Tree: velodyne_frame -> camera_frame -> right_camera_frame. The first transform carries
// T_cam_velo^-1 (the camera pose in the Velodyne frame), so a tf2 lookup (target = camera_frame,
// source = velodyne_frame) returns T_cam_velo and a Velodyne point p transformed through TF is
// T_cam_velo * p, the KITTI devkit's R_rect_00 * [R | T] (plus the cam-0 -> cam-2 shift).
// The second carries (+baseline, 0, 0): the right camera sits baseline metres along the left x.
// Exits with status 1 and a message naming the file and the problem when the calibration is
// unusable.
#include <exception>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/ros/calibration_msgs.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "kitti_calibration_publisher");
  ros::NodeHandle pnh("~");
  const std::string calib_dir = pnh.param<std::string>("calib_dir", "");
  const std::string velodyne_frame = pnh.param<std::string>("velodyne_frame", "velodyne");
  const std::string camera_frame =
      pnh.param<std::string>("camera_frame", "left_camera_optical_frame");
  const std::string right_frame =
      pnh.param<std::string>("right_camera_frame", "right_camera_optical_frame");
  if (calib_dir.empty()) {
    ROS_FATAL(
        "parameter %s is not set: give the KITTI raw date folder holding "
        "calib_cam_to_cam.txt and calib_velo_to_cam.txt",
        pnh.resolveName("calib_dir").c_str());
    return 1;
  }

  std::vector<geometry_msgs::TransformStamped> transforms;
  try {
    const lidar_stereo_fusion::kitti::Calibration calib =
        lidar_stereo_fusion::kitti::readCalibration(calib_dir);
    const ros::Time now = ros::Time::now();
    transforms.push_back(
        lidar_stereo_fusion::kittiVelodyneToCamera(calib, velodyne_frame, camera_frame, now));
    if (!right_frame.empty()) {
      transforms.push_back(
          lidar_stereo_fusion::stereoLeftToRight(calib.camera, camera_frame, right_frame, now));
    }
  } catch (const std::exception& e) {
    ROS_FATAL("cannot publish the KITTI calibration in %s: %s", calib_dir.c_str(), e.what());
    return 1;
  }

  tf2_ros::StaticTransformBroadcaster broadcaster;
  broadcaster.sendTransform(transforms);
  for (const auto& t : transforms) {
    ROS_INFO("static transform %s -> %s: t = [%.4f %.4f %.4f] m", t.header.frame_id.c_str(),
             t.child_frame_id.c_str(), t.transform.translation.x, t.transform.translation.y,
             t.transform.translation.z);
  }
  ros::spin();
  return 0;
}
