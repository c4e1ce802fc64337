// synthetic_publisher: plays the simulated street (sim::generateStreetFrame) as a live stereo +
// LiDAR rig, for demos, the RViz check and latency / rate measurements of the fusion.
//
// Publishes /stereo/{left,right}/{image_rect_color,camera_info}, /velodyne_points (stamped like the
// images: now) and the static transform left_camera_optical_frame -> velodyne.
// Private parameters: width (621), height (188) [px]; rate (10) [Hz]; frames (10) rendered once
// and then looped; rings (64); azimuth_step_deg (0.18); encoding (bgr8); publish_cloud (true).
#include <string>
#include <vector>

#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "synthetic_input.h"

namespace lsf = lidar_stereo_fusion;

int main(int argc, char** argv) {
  ros::init(argc, argv, "synthetic_publisher");
  ros::NodeHandle nh, pnh("~");
  const int width = pnh.param("width", 621);
  const int height = pnh.param("height", 188);
  const double rate = pnh.param("rate", 10.0);
  const int count = pnh.param("frames", 10);
  const int rings = pnh.param("rings", 64);
  const double azimuth_step = pnh.param("azimuth_step_deg", 0.18);
  const std::string encoding = pnh.param<std::string>("encoding", "bgr8");
  const bool publish_cloud = pnh.param("publish_cloud", true);

  ROS_INFO("synthetic_publisher: rendering %d frames of %dx%d with a %d-ring LiDAR", count, width,
           height, rings);
  const std::vector<lsf::sim::SyntheticFrame> frames =
      lsf::test::makeFrames(count, width, height, rings, azimuth_step);

  auto left_image = nh.advertise<sensor_msgs::Image>("/stereo/left/image_rect_color", 2);
  auto left_info = nh.advertise<sensor_msgs::CameraInfo>("/stereo/left/camera_info", 2);
  auto right_image = nh.advertise<sensor_msgs::Image>("/stereo/right/image_rect_color", 2);
  auto right_info = nh.advertise<sensor_msgs::CameraInfo>("/stereo/right/camera_info", 2);
  auto cloud = nh.advertise<sensor_msgs::PointCloud2>("/velodyne_points", 2);
  tf2_ros::StaticTransformBroadcaster tf;
  auto transform = lsf::test::lidarToCameraTf(frames[0].T_cam_lidar, lsf::test::kCameraFrame,
                                              lsf::test::kLidarFrame);
  transform.header.stamp = ros::Time::now();
  tf.sendTransform(transform);
  ROS_INFO("synthetic_publisher: publishing at %.1f Hz", rate);

  // A timer at the rate (ROS time, as the rig's driver would stamp), served by ros::spin().
  std::size_t i = 0;
  const ros::Timer timer = nh.createTimer(ros::Duration(1.0 / rate), [&](const ros::TimerEvent&) {
    const auto& f = frames[i++ % frames.size()];
    const ros::Time stamp = ros::Time::now();
    left_info.publish(lsf::test::cameraInfoMsg(f.camera, false, lsf::test::kCameraFrame, stamp));
    right_info.publish(
        lsf::test::cameraInfoMsg(f.camera, true, lsf::test::kRightCameraFrame, stamp));
    left_image.publish(lsf::test::imageMsg(f.left, encoding, lsf::test::kCameraFrame, stamp));
    right_image.publish(
        lsf::test::imageMsg(f.right, encoding, lsf::test::kRightCameraFrame, stamp));
    if (publish_cloud) cloud.publish(lsf::test::cloudMsg(f.cloud, lsf::test::kLidarFrame, stamp));
  });
  ros::spin();
  return 0;
}
