#include "bag_pairing.h"

#include <cinttypes>
#include <cstdio>
#include <utility>

#include <ros/message_event.h>
#include <sensor_msgs/CompressedImage.h>
#include <tf2_msgs/TFMessage.h>
#include <boost/bind/bind.hpp>

#include "lidar_stereo_fusion/ros/conversions.h"

namespace lidar_stereo_fusion {

namespace {

/// Longer than any drive's lead-in: lookups are made shortly after the sweep was read.
constexpr double kTfCacheSeconds = 60.0;
/// Undecodable images remembered, to name them in the reason of their set.
constexpr std::size_t kMaxImageProblems = 64;

std::string seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", s);
  return text;
}

}  // namespace

std::string stampName(const ros::Time& t) {
  char text[32];
  std::snprintf(text, sizeof(text), "%" PRIu32 ".%09" PRIu32, t.sec, t.nsec);
  return text;
}

BagPairing::BagPairing(const NodeParams& params, const BagTopics& topics)
    : params_(params),
      topics_(topics),
      tf_(ros::Duration(kTfCacheSeconds)),
      order_watch_({topics.left_image, topics.left_info, topics.right_image, topics.right_info}) {
  matcher_.setParams(matcherParams(params_));
  using boost::placeholders::_1;
  using boost::placeholders::_2;
  using boost::placeholders::_3;
  using boost::placeholders::_4;
  sync_ = std::make_unique<StereoSync>(params_, left_image_, left_info_, right_image_, right_info_,
                                       boost::bind(&BagPairing::onSet, this, _1, _2, _3, _4),
                                       boost::bind(&BagPairing::onDrop, this, _1, _2, _3, _4));
}

void BagPairing::addTf(const rosbag::MessageInstance& m, bool is_static) {
  const auto msg = m.instantiate<tf2_msgs::TFMessage>();
  if (!msg) return;
  for (const auto& t : msg->transforms) {
    tf_.setTransform(t, "bag", is_static);  // a bad transform is refused (and logged) by tf2
  }
}

void BagPairing::add(const rosbag::MessageInstance& m) {
  const std::string& topic = m.getTopic();
  now_ = m.getTime();
  // ROS time is the bag time, as under `rosbag play --clock`: the synchroniser reads it.
  ros::Time::setNow(now_);
  // Sets that waited ~max_sweep_wait are decided first, as the node's worker polls.
  InputMatcher::Events polled = matcher_.poll(now_);
  handle(polled);
  if (topic == topics_.left_image || topic == topics_.right_image) {
    const auto image = this->image(m);
    if (!image) return;  // undecodable: its set is skipped with the reason
    if (topic == topics_.left_image) {
      open_.emplace(image->header.stamp, now_);
      left_image_.add(ros::MessageEvent<const Image>(image, now_));
    } else {
      right_image_.add(ros::MessageEvent<const Image>(image, now_));
    }
  } else if (topic == topics_.left_info || topic == topics_.right_info) {
    const auto info = m.instantiate<Info>();
    if (!info) throw std::runtime_error(topic + " holds " + m.getDataType() + ", not a CameraInfo");
    (topic == topics_.left_info ? left_info_ : right_info_)
        .add(ros::MessageEvent<const Info>(info, now_));
  } else if (topic == topics_.cloud) {
    const auto cloud = m.instantiate<sensor_msgs::PointCloud2>();
    if (!cloud)
      throw std::runtime_error(topic + " holds " + m.getDataType() + ", not a PointCloud2");
    if (const auto rejection = checkCloud(*cloud)) {
      refused_sweep_stamp_ = cloud->header.stamp;
      refused_sweep_problem_ = rejection->problem;
      return;
    }
    InputMatcher::Events events = matcher_.addSweep(cloud->header.stamp, cloud, now_);
    handle(events);
  } else if (topic == "/tf" || topic == "/tf_static") {
    addTf(m, topic == "/tf_static");
  }
}

sensor_msgs::ImageConstPtr BagPairing::image(const rosbag::MessageInstance& m) {
  const std::string& topic = m.getTopic();
  if (m.getDataType() != "sensor_msgs/CompressedImage") {
    const auto image = m.instantiate<Image>();
    if (!image) {
      throw std::runtime_error(topic + " holds " + m.getDataType() +
                               ", not a sensor_msgs/Image or CompressedImage");
    }
    return image;
  }
  const auto compressed = m.instantiate<sensor_msgs::CompressedImage>();
  if (!compressed) throw std::runtime_error(topic + ": unreadable sensor_msgs/CompressedImage");
  try {
    return conversions::decompressImage(*compressed);
  } catch (const conversions::ConversionError& e) {
    const ros::Time& stamp = compressed->header.stamp;
    if (image_problems_.size() >= kMaxImageProblems) image_problems_.erase(image_problems_.begin());
    image_problems_[stamp] = topic + ": " + e.what();
    if (topic == topics_.left_image) {  // its set is known by the left stamp alone
      decided_.push_back({stamp, now_, boost::none, image_problems_[stamp]});
    }
    return nullptr;
  }
}

std::string BagPairing::imageProblem(const ros::Time& stamp) const {
  const auto it = image_problems_.find(stamp);
  return it == image_problems_.end() ? "" : it->second;
}

void BagPairing::finish() {
  // Far enough in the future that every waiting set has waited ~max_sweep_wait.
  const ros::Time end = now_ + ros::Duration(params_.max_sweep_wait + 1.0);
  InputMatcher::Events events = matcher_.poll(end);
  handle(events);
  for (const auto& kv : open_) {  // never completed by the synchroniser
    const std::string problem = imageProblem(kv.first);
    decided_.push_back(
        {kv.first, kv.second, boost::none,
         !problem.empty()
             ? "incomplete image set: " + problem
             : std::string("incomplete image set: no right image and camera_infos ") +
                   (params_.approximate_sync ? "near its stamp"
                                             : "with the same stamp (approximate_sync?)")});
  }
  open_.clear();
}

void BagPairing::onSet(const sensor_msgs::ImageConstPtr& left,
                       const sensor_msgs::CameraInfoConstPtr& left_info,
                       const sensor_msgs::ImageConstPtr& right,
                       const sensor_msgs::CameraInfoConstPtr& right_info) {
  ImageSet set;
  set.left = left;
  set.right = right;
  set.left_info = left_info;
  set.right_info = right_info;
  set.arrival_ros = now_;
  const ros::Time stamp = left->header.stamp;
  if (const auto rejection = checkImageSet(set)) {
    return skip(stamp, rejection->topic + ": " + rejection->problem);
  }
  if (!order_watch_.decided()) {
    if (auto warning = order_watch_.observe(set)) warnings_.push_back(std::move(*warning));
  }
  InputMatcher::Events events = matcher_.addImages(stamp, std::move(set), now_);
  if (events.out_of_order) {
    skip(stamp, "stamp not newer than the previous image set's (out of order or duplicate)");
  }
  handle(events);
}

void BagPairing::onDrop(const sensor_msgs::ImageConstPtr& left,
                        const sensor_msgs::CameraInfoConstPtr& left_info,
                        const sensor_msgs::ImageConstPtr& right,
                        const sensor_msgs::CameraInfoConstPtr& right_info) {
  if (!left) return;  // no set of ours: a lone right image or camera_info
  const std::string problem = imageProblem(left->header.stamp);
  if (!problem.empty()) return skip(left->header.stamp, "incomplete image set: " + problem);
  std::string missing;
  if (!left_info) missing += " " + topics_.left_info;
  if (!right) missing += " " + topics_.right_image;
  if (!right_info) missing += " " + topics_.right_info;
  skip(left->header.stamp, "incomplete image set dropped by the exact-time synchroniser; missing:" +
                               missing + " (different stamps? then approximate_sync true)");
}

void BagPairing::handle(InputMatcher::Events& events) {
  // A restart of time (events.restarted) throws away the sets still waiting: they stay open and
  // are named at the end (finish).
  for (std::size_t i = 0; i < events.unmatched.size(); ++i) {
    const ros::Time& stamp = events.unmatched[i];
    std::string reason;
    if (!refused_sweep_stamp_.isZero() && std::abs((refused_sweep_stamp_ - stamp).toSec()) <=
                                              params_.max_time_offset + params_.max_sweep_wait) {
      reason = "no usable sweep: the sweep at " + stampName(refused_sweep_stamp_) +
               " was refused (" + refused_sweep_problem_ + ")";
    } else if (events.unmatched_waited[i]) {
      reason = "no sweep on " + topics_.cloud + " stamped at or after it within max_sweep_wait " +
               seconds(params_.max_sweep_wait) + " s, and none before it within max_time_offset " +
               seconds(params_.max_time_offset) + " s";
    } else {
      reason = "no sweep on " + topics_.cloud + " within max_time_offset " +
               seconds(params_.max_time_offset) + " s";
    }
    skip(stamp, reason);
  }
  for (InputMatch& match : events.ready) {
    const auto it = open_.find(match.image_stamp);
    const ros::Time receipt = it != open_.end() ? it->second : match.images.arrival_ros;
    if (it != open_.end()) open_.erase(it);
    decided_.push_back({match.image_stamp, receipt, std::move(match), ""});
  }
}

void BagPairing::skip(const ros::Time& stamp, const std::string& reason) {
  const auto it = open_.find(stamp);
  if (it == open_.end()) return;  // already decided (a duplicate stamp)
  decided_.push_back({stamp, it->second, boost::none, reason});
  open_.erase(it);
}

}  // namespace lidar_stereo_fusion
