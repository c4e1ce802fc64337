// Pairing of a recorded drive's messages offline, for bag_runner: the same image-set synchroniser
// and sweep matcher as the live node (stereo_sync.h: StereoSync, FrameMatcher with matcherParams,
// checkImageSet, checkCloud), fed in bag order with ROS time = each message's bag (record) time,
// which is what the node sees under `rosbag play --clock`. Unlike the node it hands on every
// matched set (the node keeps only the newest for its busy worker) and decides every set still
// waiting at the end. TF (/tf, /tf_static) goes into a tf2::BufferCore. Images recorded as
// sensor_msgs/CompressedImage are decoded as the node decodes them (conversions::decompressImage),
// and the first sets are checked for a swapped pair (StereoOrderWatch), as the node checks them.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <message_filters/pass_through.h>
#include <rosbag/message_instance.h>
#include <tf2/buffer_core.h>
#include <boost/optional.hpp>

#include "lidar_stereo_fusion/ros/node_support.h"
#include "lidar_stereo_fusion/ros/stereo_order.h"
#include "lidar_stereo_fusion/ros/stereo_sync.h"

namespace lidar_stereo_fusion {

/// The resolved input topics (the node's relative names after remapping).
struct BagTopics {
  std::string left_image = "/stereo/left/image_rect_color";
  std::string left_info = "/stereo/left/camera_info";
  std::string right_image = "/stereo/right/image_rect_color";
  std::string right_info = "/stereo/right/camera_info";
  std::string cloud = "/velodyne_points";
};

/// What became of one image set (keyed by its left image): matched with a sweep, or skipped.
struct SetOutcome {
  ros::Time stamp;    ///< left image stamp
  ros::Time receipt;  ///< bag time of the left image message
  boost::optional<InputMatch> match;
  std::string skip_reason;  ///< why it was not matched (empty when matched)
};

class BagPairing {
 public:
  BagPairing(const NodeParams& params, const BagTopics& topics);
  BagPairing(const BagPairing&) = delete;
  BagPairing& operator=(const BagPairing&) = delete;

  /// Feeds one message of the recording (bag time order). Input topics are paired, /tf and
  /// /tf_static go into tf(); anything else is ignored. A message that cannot be read throws.
  void add(const rosbag::MessageInstance& m);
  /// Adds a /tf or /tf_static message (also used to preload /tf_static of the whole recording).
  void addTf(const rosbag::MessageInstance& m, bool is_static);
  /// End of the recording: every set still waiting is decided (as ~max_sweep_wait would).
  void finish();
  /// Decided sets, oldest first, to be taken by the caller.
  std::deque<SetOutcome>& decided() { return decided_; }
  /// Bag time of the last message fed.
  const ros::Time& now() const { return now_; }
  /// Warnings about the recording as a whole (a swapped stereo pair), each once, to be taken.
  std::vector<std::string> takeWarnings() { return std::move(warnings_); }
  const tf2::BufferCore& tf() const { return tf_; }

 private:
  using Image = sensor_msgs::Image;
  using Info = sensor_msgs::CameraInfo;
  void onSet(const sensor_msgs::ImageConstPtr& left, const sensor_msgs::CameraInfoConstPtr& li,
             const sensor_msgs::ImageConstPtr& right, const sensor_msgs::CameraInfoConstPtr& ri);
  void onDrop(const sensor_msgs::ImageConstPtr& left, const sensor_msgs::CameraInfoConstPtr& li,
              const sensor_msgs::ImageConstPtr& right, const sensor_msgs::CameraInfoConstPtr& ri);
  void handle(InputMatcher::Events& events);
  void skip(const ros::Time& stamp, const std::string& reason);
  /// An Image, or a CompressedImage decoded; null (and the problem noted) when it cannot be.
  sensor_msgs::ImageConstPtr image(const rosbag::MessageInstance& m);
  /// Why the set at `stamp` is incomplete, when one of its images could not be decoded.
  std::string imageProblem(const ros::Time& stamp) const;

  NodeParams params_;
  BagTopics topics_;
  message_filters::PassThrough<Image> left_image_, right_image_;
  message_filters::PassThrough<Info> left_info_, right_info_;
  std::unique_ptr<StereoSync> sync_;
  InputMatcher matcher_;
  tf2::BufferCore tf_;
  ros::Time now_;
  /// Left images seen and not yet decided: stamp -> bag time.
  std::map<ros::Time, ros::Time> open_;
  std::deque<SetOutcome> decided_;
  /// The last sweep refused by checkCloud, so that a set left without one says why.
  ros::Time refused_sweep_stamp_;
  std::string refused_sweep_problem_;
  std::map<ros::Time, std::string> image_problems_;  ///< images not decoded, by stamp
  StereoOrderWatch order_watch_;
  std::vector<std::string> warnings_;
};

/// "sec.nsec" with 9 digits of nanoseconds: the file name stem of a set's outputs.
std::string stampName(const ros::Time& t);

}  // namespace lidar_stereo_fusion
