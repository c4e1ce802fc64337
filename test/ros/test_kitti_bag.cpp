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
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <string>
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
#include <stereo_msgs/DisparityImage.h>
#include <tf2/buffer_core.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_msgs/TFMessage.h>
#include <opencv2/imgcodecs.hpp>

#include "bag_runner_check.h"
#include "data/data_guard.h"
#include "depth_agreement.h"
#include "kitti_bag_expected.h"
#include "kitti_bag_util.h"
#include "lidar_stereo_fusion/FusionStats.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/kitti_oxts.h"

namespace fs = std::filesystem;
namespace kitti = lidar_stereo_fusion::kitti;

namespace {

const char kDate[] = "kitti_raw/2011_09_26";
const char kDrive[] = "2011_09_26_drive_0009_sync";
const char kLeftFrame[] = "left_camera_optical_frame";
const std::vector<std::string> kReplayFrames = {"0000000000", "0000000005", "0000000010"};
/// Seconds to wait for the outputs of one frame (the pipeline takes a few seconds per frame on
/// two cores; a frame that never comes out fails the test long before rostest's time limit).
constexpr double kFrameTimeout = 240.0;

using lidar_stereo_fusion::test::kittiStamp;
using lidar_stereo_fusion::test::readBag;
using lidar_stereo_fusion::test::runCommand;

std::string scratchDir() { return lidar_stereo_fusion::test::scratchDir("test_kitti_bag"); }

std::string makeSubsetDrive(const std::vector<std::string>& frames) {
  return lidar_stereo_fusion::test::makeSubsetDrive(scratchDir(), frames);
}

/// The messages received on the fusion outputs, keyed by header stamp.
class OutputCollector {
 public:
  explicit OutputCollector(ros::NodeHandle& nh) {
    subs_.push_back(subscribe<stereo_msgs::DisparityImage>(nh, "disparity", &disparity_));
    subs_.push_back(subscribe<sensor_msgs::Image>(nh, "depth/image_rect", &depth_));
    subs_.push_back(subscribe<sensor_msgs::CameraInfo>(nh, "depth/camera_info", &depth_info_));
    subs_.push_back(subscribe<sensor_msgs::PointCloud2>(nh, "points2", &points_));
    subs_.push_back(subscribe<sensor_msgs::Image>(nh, "lidar_disparity", &lidar_disparity_));
    subs_.push_back(subscribe<lidar_stereo_fusion::FusionStats>(nh, "stats", &stats_));
  }

  /// True when every output subscription is connected to a publisher.
  bool connected() const {
    return std::all_of(subs_.begin(), subs_.end(),
                       [](const ros::Subscriber& sub) { return sub.getNumPublishers() > 0; });
  }

  /// Waits until every output has a message stamped `stamp`; returns the names of those still
  /// missing (empty on success).
  std::string waitForAll(const ros::Time& stamp, double timeout_s) {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return complete(stamp); });
    return missing(stamp);
  }

  std::mutex mutex_;
  std::condition_variable cv_;
  std::map<ros::Time, std::vector<stereo_msgs::DisparityImage::ConstPtr>> disparity_;
  std::map<ros::Time, std::vector<sensor_msgs::Image::ConstPtr>> depth_;
  std::map<ros::Time, std::vector<sensor_msgs::CameraInfo::ConstPtr>> depth_info_;
  std::map<ros::Time, std::vector<sensor_msgs::PointCloud2::ConstPtr>> points_;
  std::map<ros::Time, std::vector<sensor_msgs::Image::ConstPtr>> lidar_disparity_;
  std::map<ros::Time, std::vector<lidar_stereo_fusion::FusionStats::ConstPtr>> stats_;

 private:
  template <class Msg>
  ros::Subscriber subscribe(ros::NodeHandle& nh, const std::string& topic,
                            std::map<ros::Time, std::vector<typename Msg::ConstPtr>>* store) {
    return nh.subscribe<Msg>(topic, 10, [this, store](const typename Msg::ConstPtr& msg) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        (*store)[msg->header.stamp].push_back(msg);
      }
      cv_.notify_all();
    });
  }

  bool complete(const ros::Time& t) const { return missing(t).empty(); }

  /// The outputs without a message stamped `t` (call with mutex_ held).
  std::string missing(const ros::Time& t) const {
    std::string names;
    const auto add = [&](bool present, const char* name) {
      if (!present) names += std::string(names.empty() ? "" : ", ") + name;
    };
    add(disparity_.count(t), "disparity");
    add(depth_.count(t), "depth");
    add(depth_info_.count(t), "depth/camera_info");
    add(points_.count(t), "points2");
    add(lidar_disparity_.count(t), "lidar_disparity");
    add(stats_.count(t), "stats");
    return names;
  }

  std::vector<ros::Subscriber> subs_;
};

template <class Map>
size_t messageCount(const Map& map) {
  size_t n = 0;
  for (const auto& kv : map) n += kv.second.size();
  return n;
}

}  // namespace

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

TEST(KittiBagReplay, FusionNodeletOutputsOneSetPerFrameMatchingTheOfflineRunner) {
  LSF_REQUIRE_DATA(std::string(kDate) + "/" + kDrive);
  const std::string drive = makeSubsetDrive(kReplayFrames);
  const std::string bag_path = scratchDir() + "/replay.bag";
  fs::remove(bag_path);
  const auto [status, output] =
      runCommand(std::string(LSF_KITTI_TO_BAG) + " --kitti-raw " + drive + " --out " + bag_path);
  ASSERT_EQ(status, 0) << output;

  rosbag::Bag bag;
  auto topics = readBag(bag_path, bag);
  const auto& lefts = topics["/stereo/left/image_rect_color"];
  ASSERT_EQ(lefts.size(), kReplayFrames.size());

  ros::NodeHandle nh;
  ros::NodeHandle fusion_nh("fusion");
  OutputCollector outputs(fusion_nh);
  ros::Publisher tf_pub = nh.advertise<tf2_msgs::TFMessage>("/tf_static", 1, /*latch=*/true);
  tf_pub.publish(topics["/tf_static"].front().instantiate<tf2_msgs::TFMessage>());
  std::map<std::string, ros::Publisher> inputs;
  for (const char* topic : {"/stereo/left/image_rect_color", "/stereo/right/image_rect_color"}) {
    inputs[topic] = nh.advertise<sensor_msgs::Image>(topic, 5);
  }
  for (const char* topic : {"/stereo/left/camera_info", "/stereo/right/camera_info"}) {
    inputs[topic] = nh.advertise<sensor_msgs::CameraInfo>(topic, 5);
  }
  inputs["/velodyne_points"] = nh.advertise<sensor_msgs::PointCloud2>("/velodyne_points", 5);

  // The nodelet subscribes lazily: our output subscriptions make it subscribe to the inputs.
  // Wait for both sides, so that neither an input nor an output message can be lost.
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(60.0);
  auto connected = [&] {
    for (const auto& kv : inputs) {
      if (kv.second.getNumSubscribers() == 0) return false;
    }
    return outputs.connected();
  };
  while (!connected() && ros::WallTime::now() < give_up) ros::WallDuration(0.1).sleep();
  ASSERT_TRUE(connected()) << "the fusion nodelet did not connect to the bag's topics and ours";

  // Frame by frame: sweep, then the image set, then wait for every output of that frame.
  std::vector<ros::Time> stamps;
  for (size_t i = 0; i < lefts.size(); ++i) {
    const auto left = lefts[i].instantiate<sensor_msgs::Image>();
    stamps.push_back(left->header.stamp);
    inputs["/velodyne_points"].publish(
        topics["/velodyne_points"][i].instantiate<sensor_msgs::PointCloud2>());
    inputs["/stereo/left/camera_info"].publish(
        topics["/stereo/left/camera_info"][i].instantiate<sensor_msgs::CameraInfo>());
    inputs["/stereo/right/camera_info"].publish(
        topics["/stereo/right/camera_info"][i].instantiate<sensor_msgs::CameraInfo>());
    inputs["/stereo/right/image_rect_color"].publish(
        topics["/stereo/right/image_rect_color"][i].instantiate<sensor_msgs::Image>());
    inputs["/stereo/left/image_rect_color"].publish(left);
    const ros::WallTime start = ros::WallTime::now();
    const std::string missing = outputs.waitForAll(left->header.stamp, kFrameTimeout);
    ASSERT_EQ(missing, "") << "frame " << kReplayFrames[i] << ": no message on these outputs "
                           << "within " << kFrameTimeout << " s";
    std::printf("frame %s: outputs after %.1f s\n", kReplayFrames[i].c_str(),
                (ros::WallTime::now() - start).toSec());
  }
  ros::WallDuration(1.0).sleep();  // anything extra would arrive now

  // The offline runner on the same three frames.
  const std::string runner_out = scratchDir() + "/runner";
  fs::remove_all(runner_out);
  // Same parameter file as the nodelet's (fusion.launch loads config/fusion.yaml).
  const auto [runner_status, runner_output] =
      runCommand(std::string(LSF_KITTI_RUNNER) + " --kitti-raw " + drive + " --out " + runner_out +
                 " --params " + LSF_SOURCE_DIR + "/config/fusion.yaml");
  ASSERT_EQ(runner_status, 0) << runner_output;

  std::lock_guard<std::mutex> lock(outputs.mutex_);
  EXPECT_EQ(messageCount(outputs.disparity_), stamps.size());
  EXPECT_EQ(messageCount(outputs.depth_), stamps.size());
  EXPECT_EQ(messageCount(outputs.depth_info_), stamps.size());
  EXPECT_EQ(messageCount(outputs.points_), stamps.size());
  EXPECT_EQ(messageCount(outputs.lidar_disparity_), stamps.size());
  EXPECT_EQ(messageCount(outputs.stats_), stamps.size());

  // For the core pipeline: the nodelet's parameter file and the transform the bag carries.
  const std::string params_yaml = std::string(LSF_SOURCE_DIR) + "/config/fusion.yaml";
  const kitti::Calibration calib = kitti::readCalibration(kitti::calibrationDirOf(drive));
  const std::vector<kitti::Frame> subset_frames = kitti::listFrames(drive);
  ASSERT_EQ(subset_frames.size(), stamps.size());
  const auto tf_static = topics["/tf_static"].front().instantiate<tf2_msgs::TFMessage>();
  ASSERT_EQ(tf_static->transforms.at(0).child_frame_id, kLeftFrame);
  const Eigen::Isometry3d T_cam_velo_tf = tf2::transformToEigen(tf_static->transforms[0]).inverse();

  const auto left_info =
      topics["/stereo/left/camera_info"].front().instantiate<sensor_msgs::CameraInfo>();
  const double fx = left_info->P[0];
  const double baseline =
      -topics["/stereo/right/camera_info"].front().instantiate<sensor_msgs::CameraInfo>()->P[3] /
      fx;
  std::vector<cv::Mat1f> nodelet_depths;
  for (size_t i = 0; i < stamps.size(); ++i) {
    const ros::Time& t = stamps[i];
    SCOPED_TRACE("frame " + kReplayFrames[i]);
    const auto cloud = topics["/velodyne_points"][i].instantiate<sensor_msgs::PointCloud2>();
    const auto& disparity = outputs.disparity_[t].front();
    const auto& depth = outputs.depth_[t].front();
    const auto& depth_info = outputs.depth_info_[t].front();
    const auto& points = outputs.points_[t].front();
    const auto& prior = outputs.lidar_disparity_[t].front();
    const auto& stats = outputs.stats_[t].front();
    for (const std::string& frame_id :
         {disparity->header.frame_id, disparity->image.header.frame_id, depth->header.frame_id,
          depth_info->header.frame_id, points->header.frame_id, prior->header.frame_id,
          stats->header.frame_id}) {
      EXPECT_EQ(frame_id, kLeftFrame);
    }
    EXPECT_EQ(disparity->image.header.stamp, t);
    EXPECT_EQ(depth->encoding, "32FC1");
    EXPECT_EQ(prior->encoding, "32FC1");
    EXPECT_EQ(disparity->image.encoding, "32FC1");
    EXPECT_EQ(depth->width, 1242u);
    EXPECT_EQ(depth->height, 375u);
    EXPECT_EQ(depth_info->P, left_info->P);
    EXPECT_NEAR(disparity->f, fx, 1e-6 * fx);  // float32 fields
    EXPECT_NEAR(disparity->T, baseline, 1e-6 * baseline);
    EXPECT_GT(points->width * points->height, 10000u);
    EXPECT_EQ(stats->points_in_cloud, static_cast<int>(cloud->width));
    EXPECT_EQ(stats->rings, 64);
    EXPECT_FALSE(stats->rings_recovered);
    EXPECT_NEAR(stats->sweep_time_offset, (cloud->header.stamp - t).toSec(), 1e-4);
    EXPECT_EQ(stats->processed_frames, i + 1);
    EXPECT_EQ(stats->dropped_frames + stats->unmatched_frames + stats->tf_failures +
                  stats->invalid_inputs + stats->out_of_order + stats->processing_errors,
              0u);

    const cv::Mat1f z_ros = cv_bridge::toCvShare(depth)->image;
    const cv::Mat1f d_ros = cv_bridge::toCvShare(disparity->image, disparity)->image;
    ASSERT_EQ(z_ros.size(), cv::Size(1242, 375));
    ASSERT_EQ(d_ros.size(), z_ros.size());

    // (a) Exactly the core pipeline's answer on the KITTI files with the transform from TF: the
    // bag and the ROS conversions lose nothing.
    const cv::Mat1f expected = lidar_stereo_fusion::test::expectedDepth(
        params_yaml, subset_frames.at(i), calib, T_cam_velo_tf);
    int differ_core = 0;
    for (int y = 0; y < z_ros.rows; ++y) {
      for (int x = 0; x < z_ros.cols; ++x) {
        const float z = z_ros(y, x), ze = expected(y, x);
        const bool has = std::isfinite(z) && z > 0, has_expected = ze > 0;
        if (has != has_expected || (has && !(std::abs(z - ze) <= 1e-6f * ze))) ++differ_core;
      }
    }
    EXPECT_EQ(differ_core, 0) << "pixels where the nodelet's depth differs from the core's";

    // (b) The offline runner, which uses T_cam_velo as read (KITTI's 7-digit rotation, orthonormal
    // to ~1e-6) where TF can only carry the nearest rotation (a unit quaternion). That moves
    // projected LiDAR disparities by ~1e-5 px, enough to flip a few PatchMatch decisions: the two
    // agree on which pixels have a value, and in disparity (f B / z) all but a few pixels agree.
    // Compared in disparity (f B / z; a far pixel's depth is ill-conditioned), after rounding the
    // nodelet's depth as the PNG does (metres * 256 to an integer, clamped to 65535).
    const cv::Mat1f z_runner = kitti::readDepthPng(runner_out + "/" + kReplayFrames[i] + ".png");
    ASSERT_EQ(z_runner.size(), z_ros.size());
    int disparity_off = 0;
    for (int y = 0; y < z_ros.rows; ++y) {
      for (int x = 0; x < z_ros.cols; ++x) {
        // Depth and disparity outputs agree: z = f B / d.
        const float z = z_ros(y, x);
        if (std::isfinite(z) && z > 0 && !(std::abs(z - fx * baseline / d_ros(y, x)) <= 1e-4 * z))
          ++disparity_off;
      }
    }
    const auto agreement =
        lidar_stereo_fusion::test::agreeWithRunner(z_ros, z_runner, fx * baseline);
    const int pixels = agreement.pixels, both = agreement.both;
    const int validity_differs = agreement.validity_differs, bad_1px = agreement.bad_1px;
    const double mean_abs = agreement.mean_abs;
    nodelet_depths.push_back(z_ros.clone());
    EXPECT_EQ(disparity_off, 0);
    EXPECT_GT(both, pixels / 2);
    EXPECT_LE(validity_differs, pixels / 1000);  // 0.1 %
    EXPECT_LE(bad_1px, both / 1000);             // 0.1 %
    EXPECT_LT(mean_abs, 0.01);                   // [px]
  }
  bag.close();
  lidar_stereo_fusion::test::expectBagRunnerAgrees(bag_path, scratchDir() + "/bag_runner", stamps,
                                                   kReplayFrames, nodelet_depths, runner_out,
                                                   fx * baseline);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_kitti_bag");
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(2);
  spinner.start();
  return RUN_ALL_TESTS();
}
