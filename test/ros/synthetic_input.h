// Synthetic inputs of the fusion nodelet for the rostests and the synthetic publisher: frames of
// the simulated street (sim::generateStreetFrame) as the ROS messages a stereo + LiDAR rig sends.
//
// Keeps the core pipeline out of the ROS test sources that include it (messages only).
#pragma once

#include <string>
#include <vector>

#include <geometry_msgs/TransformStamped.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/types.h"
#include "lidar_stereo_fusion/sim/synthetic_frame.h"

namespace lidar_stereo_fusion {
namespace test {

/// Frame names used by the tests (the defaults of kitti_to_bag and fusion.launch).
constexpr char kCameraFrame[] = "left_camera_optical_frame";
constexpr char kRightCameraFrame[] = "right_camera_optical_frame";
constexpr char kLidarFrame[] = "velodyne";

/// Renders `count` consecutive frames of the street at width x height (KITTI field of view), with
/// a LiDAR of `rings` rings and azimuth step `azimuth_step_deg` (coarser = fewer points).
std::vector<sim::SyntheticFrame> makeFrames(int count, int width, int height, int rings = 64,
                                            double azimuth_step_deg = 0.36);

/// A BGR8 image as a message of `encoding` (bgra8, rgba8, bgr8, rgb8, mono8 convert the pixels;
/// any other encoding gets a zero buffer of the right size, for tests of rejected encodings).
sensor_msgs::ImagePtr imageMsg(const cv::Mat& bgr, const std::string& encoding,
                               const std::string& frame_id, const ros::Time& stamp);

/// Rectified camera_info: P = [fx 0 cx Tx; 0 fy cy 0; 0 0 1 0] with Tx = 0 (left) or
/// -fx * baseline (right, ROS convention; +fx * baseline with `positive_tx`).
sensor_msgs::CameraInfoPtr cameraInfoMsg(const StereoCamera& camera, bool right,
                                         const std::string& frame_id, const ros::Time& stamp,
                                         bool positive_tx = false);

/// The sweep in the velodyne_pointcloud layout (x, y, z, intensity float32, ring uint16, time
/// float32); with `with_ring` false the ring field is left out.
sensor_msgs::PointCloud2Ptr cloudMsg(const LidarCloud& cloud, const std::string& frame_id,
                                     const ros::Time& stamp, bool with_ring = true);

/// The static transform that makes a tf2 lookup (target camera_frame, source lidar_frame) return
/// T_cam_lidar: parent camera_frame, child lidar_frame.
geometry_msgs::TransformStamped lidarToCameraTf(const Eigen::Isometry3d& T_cam_lidar,
                                                const std::string& camera_frame,
                                                const std::string& lidar_frame);

}  // namespace test
}  // namespace lidar_stereo_fusion
