// rostest (test/ros/kitti_bag.test): real KITTI data through kitti_to_bag and the fusion nodelet.
//
//  1. kitti_to_bag on the whole sample drive: the bag holds one message per topic for every frame
//     with both images and a sweep (and none for the LiDAR-only frames), with the stamps of the
//     KITTI timestamp files, the frames, encodings, fields and calibration the rig uses; bad
//     input gives a non-zero exit status and no bag.
//  2. A 3-frame drive (symbolic links into the data, in the build folder) is converted, and the
//     bag is published frame by frame to the nodelet started by the launch file: every input set
//     yields exactly one message on each output, stamped with the left image stamp in the left
//     optical frame; the depth equals the core pipeline's on the same files with the transform
//     from the bag's TF, and agrees with the offline kitti_runner's depth PNG of the same frame
//     (which uses the calibration matrix as read) on all but a few pixels.
// Missing data fails under CI=true and skips otherwise.
//
// Part 1 is this file (with main()), part 2 test_kitti_bag_replay.cpp; one gtest binary.
#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include <cv_bridge/cv_bridge.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2/buffer_core.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_msgs/TFMessage.h>
#include <opencv2/imgcodecs.hpp>

#include "data/data_guard.h"
#include "kitti_bag_test.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/kitti_oxts.h"

namespace fs = std::filesystem;
namespace kitti = lidar_stereo_fusion::kitti;
using namespace kitti_bag_test;  // NOLINT: the names of this rostest

/// /tf_static's third transform is imu_link -> velodyne (calib_imu_to_velo.txt inverted); /tf holds
/// odom -> imu_link at every oxts stamp (all 19 packets bracket the frames 0 .. 50), the devkit
/// poses relative to the first packet's; through both, TF finds the Velodyne in odom.
void expectEgoMotion(const std::string& date, const std::string& drive,
                     const tf2_msgs::TFMessage& tf_static,
                     const std::vector<rosbag::MessageInstance>& tf_messages) {
  const geometry_msgs::TransformStamped& imu_velo = tf_static.transforms.at(2);
  EXPECT_EQ(imu_velo.header.frame_id, "imu_link");
  EXPECT_EQ(imu_velo.child_frame_id, "velodyne");
  const Eigen::Isometry3d T_velo_imu = kitti::readImuToVelo(date);
  EXPECT_TRUE(tf2::transformToEigen(imu_velo).isApprox(T_velo_imu.inverse(), 1e-9));
  EXPECT_NEAR(imu_velo.transform.translation.x, 0.81, 0.01);  // the IMU is 0.81 m behind

  const auto samples = kitti::readOxtsDrive(drive);
  const auto poses = kitti::posesRelativeToFirst(samples);
  ASSERT_EQ(tf_messages.size(), samples.size());
  tf2::BufferCore buffer(ros::Duration(100.0));
  buffer.setTransform(imu_velo, "bag", true);
  for (size_t i = 0; i < samples.size(); ++i) {
    SCOPED_TRACE(samples[i].name);
    const auto msg = tf_messages[i].instantiate<tf2_msgs::TFMessage>();
    ASSERT_TRUE(msg);
    ASSERT_EQ(msg->transforms.size(), 1u);
    const geometry_msgs::TransformStamped& t = msg->transforms[0];
    EXPECT_EQ(t.header.frame_id, "odom");
    EXPECT_EQ(t.child_frame_id, "imu_link");
    EXPECT_NEAR(t.header.stamp.toSec(), samples[i].stamp, 1e-6);
    EXPECT_EQ(tf_messages[i].getTime(), t.header.stamp);
    EXPECT_TRUE(tf2::transformToEigen(t).isApprox(poses[i], 1e-9));
    buffer.setTransform(t, "bag");
  }
  EXPECT_TRUE(tf2::transformToEigen(
                  tf_messages.front().instantiate<tf2_msgs::TFMessage>()->transforms.at(0))
                  .isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  // Frame 20's image instant, within 2 ms of packet 20 (interpolated from packets 19 and 20): the
  // Velodyne within centimetres of its pose at packet 20, ~21 m (2 s at ~10.5 m/s) from the start.
  const ros::Time image20(kittiStamp(drive + "/image_02/timestamps.txt", "0000000020"));
  const Eigen::Isometry3d odom_velo =
      tf2::transformToEigen(buffer.lookupTransform("odom", "velodyne", image20));
  ASSERT_EQ(samples[8].name, "0000000020");  // 0, 5, 10, 15, 16 .. 19, 20
  const Eigen::Isometry3d at_20 = poses[8] * T_velo_imu.inverse();
  EXPECT_NEAR((odom_velo.translation() - at_20.translation()).norm(), 0.0, 0.05);
  EXPECT_GT(at_20.translation().norm(), 18.0);
  EXPECT_LT(at_20.translation().norm(), 24.0);
}

TEST(KittiToBag, WritesTheRigTopicsForEveryCompleteFrame) {
  LSF_REQUIRE_DATA(std::string(kDate) + "/" + kDrive);
  const std::string date = lidar_stereo_fusion::test::dataPath(kDate);
  const std::string drive = date + "/" + kDrive;
  const std::string bag_path = scratchDir() + "/whole_drive.bag";
  fs::remove(bag_path);
  const auto [status, output] =
      runCommand(std::string(LSF_KITTI_TO_BAG) + " --kitti-raw " + drive + " --out " + bag_path);
  ASSERT_EQ(status, 0) << output;
  // The LiDAR-only frames are named as skipped.
  EXPECT_NE(output.find("0000000016"), std::string::npos) << output;

  const std::vector<kitti::Frame> frames = kitti::listFrames(drive);
  ASSERT_EQ(frames.size(), 11u);
  const kitti::Calibration calib = kitti::readCalibration(date);
  rosbag::Bag bag;
  auto topics = readBag(bag_path, bag);
  ASSERT_EQ(topics.size(), 7u);  // the rig's six and the oxts ego-motion on /tf
  for (const char* topic :
       {"/stereo/left/image_rect_color", "/stereo/left/camera_info",
        "/stereo/right/image_rect_color", "/stereo/right/camera_info", "/velodyne_points"}) {
    EXPECT_EQ(topics[topic].size(), frames.size()) << topic;
  }
  ASSERT_EQ(topics["/tf_static"].size(), 1u);
  ASSERT_EQ(topics["/velodyne_points"].size(), frames.size());
  ASSERT_EQ(topics["/stereo/left/image_rect_color"].size(), frames.size());

  // /tf_static: latched on replay, velodyne -> left (T_cam_velo^-1), left -> right (+B in x).
  const auto& tf_instance = topics["/tf_static"].front();
  ASSERT_TRUE(tf_instance.getConnectionHeader());
  EXPECT_EQ(tf_instance.getConnectionHeader()->at("latching"), "1");
  const auto tf = tf_instance.instantiate<tf2_msgs::TFMessage>();
  ASSERT_TRUE(tf);
  ASSERT_EQ(tf->transforms.size(), 3u);
  EXPECT_EQ(tf->transforms[0].header.frame_id, "velodyne");
  EXPECT_EQ(tf->transforms[0].child_frame_id, kLeftFrame);
  const Eigen::Vector3d camera_in_velodyne = calib.T_cam_velo.inverse().translation();
  EXPECT_NEAR(tf->transforms[0].transform.translation.x, camera_in_velodyne.x(), 1e-9);
  EXPECT_NEAR(tf->transforms[0].transform.translation.y, camera_in_velodyne.y(), 1e-9);
  EXPECT_NEAR(tf->transforms[0].transform.translation.z, camera_in_velodyne.z(), 1e-9);
  EXPECT_EQ(tf->transforms[1].header.frame_id, kLeftFrame);
  EXPECT_EQ(tf->transforms[1].child_frame_id, "right_camera_optical_frame");
  EXPECT_NEAR(tf->transforms[1].transform.translation.x, calib.camera.baseline, 1e-9);
  expectEgoMotion(date, drive, *tf, topics["/tf"]);

  for (size_t i = 0; i < frames.size(); ++i) {
    const std::string& name = frames[i].name;
    SCOPED_TRACE("frame " + name);
    const auto left = topics["/stereo/left/image_rect_color"][i].instantiate<sensor_msgs::Image>();
    const auto right =
        topics["/stereo/right/image_rect_color"][i].instantiate<sensor_msgs::Image>();
    const auto left_info =
        topics["/stereo/left/camera_info"][i].instantiate<sensor_msgs::CameraInfo>();
    const auto right_info =
        topics["/stereo/right/camera_info"][i].instantiate<sensor_msgs::CameraInfo>();
    const auto cloud = topics["/velodyne_points"][i].instantiate<sensor_msgs::PointCloud2>();
    ASSERT_TRUE(left && right && left_info && right_info && cloud);

    // Stamps from the KITTI files: one stamp for the stereo pair, the sweep end for the cloud.
    const double image_stamp = kittiStamp(drive + "/image_02/timestamps.txt", name);
    const double sweep_end = kittiStamp(drive + "/velodyne_points/timestamps_end.txt", name);
    EXPECT_NEAR(left->header.stamp.toSec(), image_stamp, 1e-6);
    EXPECT_EQ(right->header.stamp, left->header.stamp);
    EXPECT_EQ(left_info->header.stamp, left->header.stamp);
    EXPECT_EQ(right_info->header.stamp, left->header.stamp);
    EXPECT_NEAR(cloud->header.stamp.toSec(), sweep_end, 1e-6);
    const double offset = (cloud->header.stamp - left->header.stamp).toSec();
    EXPECT_GT(offset, 0.0);  // near, not equal
    EXPECT_LT(offset, 0.1);
    EXPECT_EQ(topics["/velodyne_points"][i].getTime(), cloud->header.stamp);

    EXPECT_EQ(left->header.frame_id, kLeftFrame);
    EXPECT_EQ(left_info->header.frame_id, kLeftFrame);
    EXPECT_EQ(right->header.frame_id, "right_camera_optical_frame");
    EXPECT_EQ(right_info->header.frame_id, "right_camera_optical_frame");
    EXPECT_EQ(cloud->header.frame_id, "velodyne");
    EXPECT_EQ(left->encoding, "bgr8");
    EXPECT_EQ(right->encoding, "bgr8");
    EXPECT_EQ(left->width, 1242u);
    EXPECT_EQ(left->height, 375u);
    EXPECT_EQ(left_info->width, left->width);
    EXPECT_EQ(left_info->height, left->height);
    // Pixels are the PNG's (BGR order).
    if (i == 0) {
      const cv::Mat png = cv::imread(frames[i].left_image, cv::IMREAD_COLOR);
      const cv::Mat msg_image = cv_bridge::toCvShare(left)->image;
      EXPECT_EQ(cv::norm(png, msg_image, cv::NORM_INF), 0.0);
    }
    // Rectified pair: right P has Tx = -fx * B.
    EXPECT_DOUBLE_EQ(left_info->P[0], calib.camera.fx);
    EXPECT_DOUBLE_EQ(left_info->P[3], 0.0);
    EXPECT_NEAR(right_info->P[3], -calib.camera.fx * calib.camera.baseline, 1e-9);
    EXPECT_NEAR(-right_info->P[3] / right_info->P[0], 0.5327, 1e-3);

    // Cloud: every point of the .bin, fields with the types of velodyne_pointcloud.
    const kitti::Frame& f = frames[i];
    const auto points = kitti::readVelodyneBin(f.velodyne);
    ASSERT_EQ(cloud->width * cloud->height, points.size());
    std::map<std::string, uint8_t> types;
    for (const auto& field : cloud->fields) types[field.name] = field.datatype;
    using sensor_msgs::PointField;
    EXPECT_EQ(types["x"], PointField::FLOAT32);
    EXPECT_EQ(types["intensity"], PointField::FLOAT32);
    EXPECT_EQ(types["ring"], PointField::UINT16);
    EXPECT_EQ(types["time"], PointField::FLOAT32);
    sensor_msgs::PointCloud2ConstIterator<float> x(*cloud, "x"), intensity(*cloud, "intensity"),
        time(*cloud, "time");
    sensor_msgs::PointCloud2ConstIterator<uint16_t> ring(*cloud, "ring");
    std::set<uint16_t> rings;
    float min_time = 1.f, max_time = -1.f;
    for (size_t k = 0; k < points.size(); ++k, ++x, ++intensity, ++time, ++ring) {
      if (x[0] != points[k].x || x[1] != points[k].y || x[2] != points[k].z ||
          *intensity != points[k].intensity) {
        ADD_FAILURE() << "point " << k << " differs from the .bin";
        break;
      }
      rings.insert(*ring);
      min_time = std::min(min_time, *time);
      max_time = std::max(max_time, *time);
    }
    EXPECT_EQ(rings.size(), 64u);
    EXPECT_EQ(*rings.rbegin(), 63);
    // Stamped at the sweep end: point times span the previous revolution (~0.1 s), up to 0.
    EXPECT_LE(max_time, 0.f);
    EXPECT_GT(max_time, -0.01f);
    EXPECT_LT(min_time, -0.09f);
    EXPECT_GT(min_time, -0.11f);
  }
  bag.close();
  fs::remove(bag_path);  // 60 MB
}

TEST(KittiToBag, BadInputFailsWithoutWritingABag) {
  const std::string bag_path = scratchDir() + "/bad.bag";
  fs::remove(bag_path);
  auto [status, output] = runCommand(std::string(LSF_KITTI_TO_BAG) + " --kitti-raw " +
                                     scratchDir() + "/no_such_drive --out " + bag_path);
  EXPECT_EQ(status, 1) << output;
  EXPECT_NE(output.find("no_such_drive"), std::string::npos) << output;
  std::tie(status, output) = runCommand(std::string(LSF_KITTI_TO_BAG) + " --out " + bag_path);
  EXPECT_EQ(status, 2) << output;
  EXPECT_NE(output.find("--kitti-raw"), std::string::npos) << output;
  std::tie(status, output) = runCommand(std::string(LSF_KITTI_TO_BAG) + " --kitti-raw x --out " +
                                        bag_path + " --frames -3");
  EXPECT_EQ(status, 2) << output;
  EXPECT_FALSE(fs::exists(bag_path));
  EXPECT_FALSE(fs::exists(bag_path + ".partial"));
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_kitti_bag");
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(2);
  spinner.start();
  return RUN_ALL_TESTS();
}
