// rostest (test/ros/kitti_bag.test), part 2 (see test_kitti_bag.cpp): a 3-frame drive (symbolic
// links into the data, in the build folder) is converted, and the bag is published frame by frame
// to the nodelet started by the launch file: every input set yields exactly one message on each
// output, stamped with the left image stamp in the left optical frame; the depth equals the core
// pipeline's on the same files with the transform from the bag's TF, and agrees with the offline
// kitti_runner's depth PNG of the same frame (which uses the calibration matrix as read) on all
// but a few pixels; bag_runner's PNGs agree with both.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <cv_bridge/cv_bridge.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <stereo_msgs/DisparityImage.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_msgs/TFMessage.h>

#include "bag_runner_check.h"
#include "child_process.h"
#include "data/data_guard.h"
#include "depth_agreement.h"
#include "kitti_bag_expected.h"
#include "kitti_bag_test.h"
#include "lidar_stereo_fusion/FusionStats.h"
#include "lidar_stereo_fusion/io/kitti.h"

namespace fs = std::filesystem;
namespace kitti = lidar_stereo_fusion::kitti;
using namespace kitti_bag_test;  // NOLINT: the names of this rostest

namespace {

const std::vector<std::string> kReplayFrames = {"0000000000", "0000000005", "0000000010"};
/// Seconds to wait for the outputs of one frame (the pipeline takes a few seconds per frame on
/// two cores; a frame that never comes out fails the test long before rostest's time limit).
constexpr double kFrameTimeout = 240.0;

std::string makeSubsetDrive(const std::vector<std::string>& frames) {
  return lidar_stereo_fusion::test::makeSubsetDrive(scratchDir(), frames);
}

/// Messages in a map of message lists.
template <class Map>
size_t messageCount(const Map& map) {
  size_t n = 0;
  for (const auto& kv : map) n += kv.second.size();
  return n;
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

  /// Waits at most `timeout_s` for a message beyond the `expected` of some output (a set
  /// published twice); true when one came.
  bool extraArrives(size_t expected, double timeout_s) {
    std::unique_lock<std::mutex> lock(mutex_);
    return cv_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] {
      return messageCount(disparity_) > expected || messageCount(depth_) > expected ||
             messageCount(depth_info_) > expected || messageCount(points_) > expected ||
             messageCount(lidar_disparity_) > expected || messageCount(stats_) > expected;
    });
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

}  // namespace

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
  auto connected = [&] {
    for (const auto& kv : inputs) {
      if (kv.second.getNumSubscribers() == 0) return false;
    }
    return outputs.connected();
  };
  ASSERT_TRUE(lidar_stereo_fusion::test::waitFor(60.0, connected))
      << "the fusion nodelet did not connect to the bag's topics and ours";

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
  // No output follows the last frame's (a topic delivers in order: an extra message of an earlier
  // frame would have come before it).
  EXPECT_FALSE(outputs.extraArrives(stamps.size(), 1.0)) << "an output published twice";

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
