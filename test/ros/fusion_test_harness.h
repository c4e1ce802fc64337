// The test harness of the fusion node's rostest (test_fusion_node*.cpp, one gtest binary):
// publishes synthetic input sets (and bad ones) to the fusion node and records its outputs and
// /rosout.
#pragma once

#include <algorithm>
#include <chrono>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <ros/master.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <stereo_msgs/DisparityImage.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include "lidar_stereo_fusion/FusionStats.h"
#include "synthetic_input.h"

namespace fusion_test {

namespace lsf = lidar_stereo_fusion;
using lsf::test::kCameraFrame;
using lsf::test::kLidarFrame;
using lsf::test::kRightCameraFrame;

constexpr int kWidth = 320, kHeight = 120;
constexpr double kOutputTimeout = 20.0;  ///< [s] first frame includes pipeline warm-up

/// The output topics, relative to the fusion namespace.
const std::vector<std::string> kOutputs = {
    "disparity",       "depth/image_rect", "depth/camera_info",     "depth/image_color", "points2",
    "lidar_disparity", "disparity_image",  "disparity_image_color", "confidence",        "stats"};

/// How one input set is made.
struct SetSpec {
  int frame = 0;
  std::string left_encoding = "bgr8", right_encoding = "bgr8";
  int right_width = 0;  ///< 0 = same as the left image
  enum class Cloud { kNormal, kNone, kEmpty, kNaN, kNoRing, kCustom } cloud = Cloud::kNormal;
  sensor_msgs::PointCloud2Ptr custom_cloud;
  sensor_msgs::ImagePtr custom_left;  ///< published instead of the left image (stamp set here)
  std::string cloud_frame = kLidarFrame;
  double cloud_offset = 0.0;        ///< sweep stamp - image stamp [s]
  bool cloud_first = false;         ///< publish the sweep before the images
  bool positive_tx = false;         ///< right camera_info with Tx = +fx * B
  double right_stamp_offset = 0.0;  ///< right image/info stamp - left stamp [s]
  bool left_info_zero = false;      ///< left camera_info with all-zero K and P
};

class Harness {
 public:
  Harness() : pnh_("~") {
    process_node_ = pnh_.param<std::string>("process_node", "/fusion/fusion_manager");
    fusion_node_ = pnh_.param<std::string>("fusion_node", "/fusion/fusion");
    ns_ = pnh_.param<std::string>("fusion_ns", "/fusion");
    // stereo_image_proc (image_geometry) needs both camera_infos in one frame: the left one.
    right_frame_ = pnh_.param<std::string>("right_frame", kRightCameraFrame);
    frames_ = lsf::test::makeFrames(3, kWidth, kHeight);
    left_image_ = nh_.advertise<sensor_msgs::Image>("/stereo/left/image_rect_color", 5);
    left_info_ = nh_.advertise<sensor_msgs::CameraInfo>("/stereo/left/camera_info", 5);
    right_image_ = nh_.advertise<sensor_msgs::Image>("/stereo/right/image_rect_color", 5);
    right_info_ = nh_.advertise<sensor_msgs::CameraInfo>("/stereo/right/camera_info", 5);
    cloud_ = nh_.advertise<sensor_msgs::PointCloud2>("/velodyne_points", 5);
    rosout_ = nh_.subscribe("/rosout", 200, &Harness::logCb, this);
    addStaticTf(frames_[0].T_cam_lidar, kLidarFrame);
    last_stamp_ = ros::Time::now();
  }

  const std::vector<lsf::sim::SyntheticFrame>& frames() const { return frames_; }
  const std::string& processNode() const { return process_node_; }
  const std::string& fusionNode() const { return fusion_node_; }
  std::string output(const std::string& name) const { return ns_ + "/" + name; }

  void addStaticTf(const Eigen::Isometry3d& T_cam_lidar, const std::string& lidar_frame) {
    tfs_.push_back(lsf::test::lidarToCameraTf(T_cam_lidar, kCameraFrame, lidar_frame));
    tfs_.back().header.stamp = ros::Time::now();
    tf_broadcaster_.sendTransform(tfs_);
  }

  // --- inputs ------------------------------------------------------------------------------------
  std::vector<ros::Publisher*> inputs() {
    return {&left_image_, &left_info_, &right_image_, &right_info_, &cloud_};
  }
  bool inputsSubscribed(bool expected, double timeout) {
    return waitFor(timeout, [&] {
      for (auto* p : inputs()) {
        if ((p->getNumSubscribers() > 0) != expected) return false;
      }
      return true;
    });
  }

  /// A stamp newer than every one used so far (0.2 s apart, so that sweeps of consecutive sets
  /// are further apart than max_time_offset).
  ros::Time nextStamp() {
    const ros::Time now = ros::Time::now();
    last_stamp_ = std::max(now, last_stamp_ + ros::Duration(0.2));
    return last_stamp_;
  }

  /// nextStamp() once the clock has reached it (sets sent in a burst run ahead of it), for a test
  /// that checks the latency (publish time - stamp) of its sets. Waits at most 10 s.
  ros::Time nextStampNotAhead() {
    const ros::Time stamp = nextStamp();
    waitFor(10.0, [&] { return ros::Time::now() >= stamp; });
    return stamp;
  }

  sensor_msgs::PointCloud2Ptr makeCloud(const SetSpec& spec, const ros::Time& stamp) const {
    const auto& frame = frames_[spec.frame % frames_.size()];
    const ros::Time cloud_stamp = stamp + ros::Duration(spec.cloud_offset);
    switch (spec.cloud) {
      case SetSpec::Cloud::kNone:
        return nullptr;
      case SetSpec::Cloud::kEmpty:
        return lsf::test::cloudMsg({}, spec.cloud_frame, cloud_stamp);
      case SetSpec::Cloud::kNaN: {
        lsf::LidarCloud nan_cloud(500);
        for (auto& p : nan_cloud) p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
        return lsf::test::cloudMsg(nan_cloud, spec.cloud_frame, cloud_stamp);
      }
      case SetSpec::Cloud::kNoRing:
        return lsf::test::cloudMsg(frame.cloud, spec.cloud_frame, cloud_stamp, false);
      case SetSpec::Cloud::kCustom: {
        auto cloud = boost::make_shared<sensor_msgs::PointCloud2>(*spec.custom_cloud);
        cloud->header.stamp = cloud_stamp;
        return cloud;
      }
      case SetSpec::Cloud::kNormal:
      default:
        return lsf::test::cloudMsg(frame.cloud, spec.cloud_frame, cloud_stamp);
    }
  }

  /// Publishes one input set stamped `stamp`.
  void publishSet(const SetSpec& spec, const ros::Time& stamp) {
    const auto& frame = frames_[spec.frame % frames_.size()];
    const ros::Time right_stamp = stamp + ros::Duration(spec.right_stamp_offset);
    sensor_msgs::ImagePtr left =
        spec.custom_left ? boost::make_shared<sensor_msgs::Image>(*spec.custom_left)
                         : lsf::test::imageMsg(frame.left, spec.left_encoding, kCameraFrame, stamp);
    left->header.stamp = stamp;
    left->header.frame_id = kCameraFrame;
    cv::Mat right_bgr = frame.right;
    lsf::StereoCamera right_camera = frame.camera;
    if (spec.right_width > 0) {
      right_bgr = frame.right(cv::Rect(0, 0, spec.right_width, frame.right.rows)).clone();
      right_camera.width = spec.right_width;
    }
    auto right = lsf::test::imageMsg(right_bgr, spec.right_encoding, right_frame_, right_stamp);
    auto linfo = lsf::test::cameraInfoMsg(frame.camera, false, kCameraFrame, stamp);
    if (spec.left_info_zero) {
      linfo->K.fill(0.0);
      linfo->P.fill(0.0);
    }
    auto rinfo =
        lsf::test::cameraInfoMsg(right_camera, true, right_frame_, right_stamp, spec.positive_tx);
    auto cloud = makeCloud(spec, stamp);
    if (cloud && spec.cloud_first) cloud_.publish(cloud);
    left_info_.publish(linfo);
    right_info_.publish(rinfo);
    left_image_.publish(left);
    right_image_.publish(right);
    if (cloud && !spec.cloud_first) cloud_.publish(cloud);
  }

  // --- outputs -----------------------------------------------------------------------------------
  void subscribeOutputs(const std::vector<std::string>& names = kOutputs) {
    for (const auto& name : names) {
      const std::string topic = output(name);
      if (name == "disparity") {
        subs_.push_back(nh_.subscribe<stereo_msgs::DisparityImage>(
            topic, 5, [this](const stereo_msgs::DisparityImageConstPtr& m) {
              record("disparity", m->header, [&] { disparity_ = m; });
            }));
      } else if (name == "depth/camera_info") {
        subs_.push_back(nh_.subscribe<sensor_msgs::CameraInfo>(
            topic, 5, [this](const sensor_msgs::CameraInfoConstPtr& m) {
              record("depth/camera_info", m->header, [&] { depth_info_ = m; });
            }));
      } else if (name == "points2") {
        subs_.push_back(nh_.subscribe<sensor_msgs::PointCloud2>(
            topic, 5, [this](const sensor_msgs::PointCloud2ConstPtr& m) {
              record("points2", m->header, [&] { points_ = m; });
            }));
      } else if (name == "stats") {
        subs_.push_back(
            nh_.subscribe<lsf::FusionStats>(topic, 20, [this](const lsf::FusionStatsConstPtr& m) {
              record("stats", m->header, [&] { stats_ = m; });
            }));
      } else {  // images
        subs_.push_back(nh_.subscribe<sensor_msgs::Image>(
            topic, 5, [this, name](const sensor_msgs::ImageConstPtr& m) {
              record(name, m->header, [&] { images_[name] = m; });
            }));
      }
    }
  }
  /// Every output subscriber is connected to the nodelet (outputs without a connection are not
  /// computed, so a set published before would miss them).
  bool outputsConnected(double timeout = 10.0) {
    return waitFor(timeout, [&] {
      for (const auto& s : subs_) {
        if (s.getNumPublishers() == 0) return false;
      }
      return true;
    });
  }
  void unsubscribeOutputs() {
    for (auto& s : subs_) s.shutdown();
    subs_.clear();
  }

  /// Number of messages received on `name` stamped `stamp`.
  int count(const std::string& name, const ros::Time& stamp) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = received_.find(name);
    if (it == received_.end()) return 0;
    const auto jt = it->second.find(stamp.toNSec());
    return jt == it->second.end() ? 0 : jt->second;
  }
  /// True when every output got a message stamped `stamp` within `timeout`.
  bool waitForOutputs(const ros::Time& stamp, double timeout = kOutputTimeout) {
    return waitFor(timeout, [&] {
      for (const auto& name : kOutputs) {
        if (count(name, stamp) == 0) return false;
      }
      return true;
    });
  }
  /// Number of outputs that got anything stamped `stamp` so far.
  int outputsSoFar(const ros::Time& stamp) {
    int n = 0;
    for (const auto& name : kOutputs) n += count(name, stamp);
    return n;
  }
  /// Forgets the latest output messages (not the counts per stamp), so that a test reads only
  /// what came out for its own sets.
  void forgetLatestOutputs() {
    std::lock_guard<std::mutex> lock(mutex_);
    frame_ids_.clear();
    disparity_.reset();
    images_.clear();
    depth_info_.reset();
    points_.reset();
    stats_.reset();
  }
  std::string frameId(const std::string& name) {
    std::lock_guard<std::mutex> lock(mutex_);
    return frame_ids_[name];
  }
  lsf::FusionStatsConstPtr stats() {
    std::lock_guard<std::mutex> lock(mutex_);
    return stats_;
  }
  stereo_msgs::DisparityImageConstPtr disparity() {
    std::lock_guard<std::mutex> lock(mutex_);
    return disparity_;
  }
  sensor_msgs::ImageConstPtr image(const std::string& name) {
    std::lock_guard<std::mutex> lock(mutex_);
    return images_[name];
  }
  sensor_msgs::CameraInfoConstPtr depthInfo() {
    std::lock_guard<std::mutex> lock(mutex_);
    return depth_info_;
  }
  sensor_msgs::PointCloud2ConstPtr points() {
    std::lock_guard<std::mutex> lock(mutex_);
    return points_;
  }

  // --- logs --------------------------------------------------------------------------------------
  std::size_t logMark() {
    std::lock_guard<std::mutex> lock(mutex_);
    return logs_.size();
  }
  /// Waits for a WARN or ERROR logged after `mark` that contains every one of `parts`.
  bool waitForLog(std::size_t mark, const std::vector<std::string>& parts, double timeout = 5.0) {
    return waitFor(timeout, [&] {
      std::lock_guard<std::mutex> lock(mutex_);
      for (std::size_t i = mark; i < logs_.size(); ++i) {
        if (logs_[i].level < rosgraph_msgs::Log::WARN) continue;
        bool all = true;
        for (const auto& p : parts) all = all && logs_[i].msg.find(p) != std::string::npos;
        if (all) return true;
      }
      return false;
    });
  }
  std::vector<std::string> warningsSince(std::size_t mark) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> out;
    for (std::size_t i = mark; i < logs_.size(); ++i) {
      if (logs_[i].level >= rosgraph_msgs::Log::WARN) out.push_back(logs_[i].msg);
    }
    return out;
  }
  std::string logsSince(std::size_t mark) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::string out;
    for (std::size_t i = mark; i < logs_.size(); ++i) out += "\n  " + logs_[i].msg;
    return out;
  }

  /// [s] the node's ~log_throttle_period (the .test files set it short; default 5 s).
  double throttlePeriod() const {
    double period = 5.0;
    ros::param::get(fusion_node_ + "/log_throttle_period", period);
    return period;
  }
  /// Waits until a throttle period has passed since the last WARN or ERROR of the process under
  /// test arrived, so that every (topic, kind) may be logged again.
  bool waitForThrottleExpiry(double timeout) {
    const auto period = std::chrono::duration<double>(throttlePeriod());
    return waitFor(timeout, [&] {
      std::lock_guard<std::mutex> lock(mutex_);
      return std::chrono::steady_clock::now() - last_warning_ >= period;
    });
  }
  /// The nodelet is up: its outputs are advertised.
  bool nodeUp(double timeout) {
    return waitFor(timeout, [&] {
      ros::master::V_TopicInfo topics;
      ros::master::getTopics(topics);
      for (const auto& t : topics) {
        if (t.name == output("stats")) return true;
      }
      return false;
    });
  }

  /// The process hosting the nodelet is registered with the master.
  bool processAlive() {
    std::vector<std::string> nodes;
    if (!ros::master::getNodes(nodes)) return false;
    return std::find(nodes.begin(), nodes.end(), process_node_) != nodes.end();
  }

  static bool waitFor(double timeout, const std::function<bool()>& condition) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
    while (std::chrono::steady_clock::now() < end) {
      if (condition()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return condition();
  }

 private:
  template <class Store>
  void record(const std::string& name, const std_msgs::Header& header, Store store) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++received_[name][header.stamp.toNSec()];
    frame_ids_[name] = header.frame_id;
    store();
  }
  void logCb(const rosgraph_msgs::LogConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    logs_.push_back(*msg);
    if (msg->level >= rosgraph_msgs::Log::WARN && msg->name == process_node_) {
      last_warning_ = std::chrono::steady_clock::now();
    }
  }

  ros::NodeHandle nh_, pnh_;
  std::string process_node_, fusion_node_, ns_, right_frame_;
  std::vector<lsf::sim::SyntheticFrame> frames_;
  ros::Publisher left_image_, left_info_, right_image_, right_info_, cloud_;
  tf2_ros::StaticTransformBroadcaster tf_broadcaster_;
  std::vector<geometry_msgs::TransformStamped> tfs_;
  ros::Subscriber rosout_;
  std::vector<ros::Subscriber> subs_;
  ros::Time last_stamp_;

  std::mutex mutex_;
  std::map<std::string, std::map<uint64_t, int>> received_;
  std::map<std::string, std::string> frame_ids_;
  stereo_msgs::DisparityImageConstPtr disparity_;
  std::map<std::string, sensor_msgs::ImageConstPtr> images_;
  sensor_msgs::CameraInfoConstPtr depth_info_;
  sensor_msgs::PointCloud2ConstPtr points_;
  lsf::FusionStatsConstPtr stats_;
  std::vector<rosgraph_msgs::Log> logs_;
  std::chrono::steady_clock::time_point last_warning_;  ///< arrival of the last one
};

}  // namespace fusion_test
