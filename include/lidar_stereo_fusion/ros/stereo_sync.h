// The pairing of the fusion's inputs, shared by the live node (InputGate, fed by subscriptions)
// and bag_runner (fed from a bag): the image-set synchroniser (message_filters ExactTime or
// ApproximateTime over left image, left camera_info, right image, right camera_info, ~queue_size
// per topic) and the parameters of the sweep matcher (FrameMatcher: ~max_time_offset,
// ~max_sweep_wait, ~sweep_buffer_size). One place, so a bag pairs offline exactly as it does live.
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include <message_filters/sync_policies/approximate_time.h>
#include <message_filters/sync_policies/exact_time.h>
#include <message_filters/synchronizer.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <boost/bind/bind.hpp>
#include <boost/function.hpp>
#include <boost/optional.hpp>

#include "lidar_stereo_fusion/ros/frame_matcher.h"
#include "lidar_stereo_fusion/ros/node_support.h"

namespace lidar_stereo_fusion {

/// A synchronised stereo pair with its camera_infos, as it arrived.
struct ImageSet {
  sensor_msgs::ImageConstPtr left, right;
  sensor_msgs::CameraInfoConstPtr left_info, right_info;
  ros::Time arrival_ros;                               ///< ROS time when the set was complete
  std::chrono::steady_clock::time_point arrival_wall;  ///< the same in wall time
  uint32_t clock_epoch = 0;                            ///< InputGate::clockEpoch() at arrival
};
using InputMatcher = FrameMatcher<ImageSet, sensor_msgs::PointCloud2ConstPtr>;
using InputMatch = InputMatcher::Match;

/// Why a message was refused: the input topic (relative), a fixed word for the kind of problem
/// (the throttle key) and the problem itself.
struct Rejection {
  std::string topic, kind, problem;
};

/// Checks of an image set that need no state: encodings, sizes, camera_infos against the images,
/// a usable (and plausible) calibration, a frame_id. Pure; none when the set is usable.
boost::optional<Rejection> checkImageSet(const ImageSet& set);
/// Checks of a sweep: layout (conversions::checkCloudLayout), not empty, a frame_id.
boost::optional<Rejection> checkCloud(const sensor_msgs::PointCloud2& cloud);

/// The sweep matcher's parameters from the node parameters.
inline InputMatcher::Params matcherParams(const NodeParams& p) {
  InputMatcher::Params mp;
  mp.max_time_offset = p.max_time_offset;
  mp.max_wait = p.max_sweep_wait;
  mp.sweep_buffer_size = static_cast<std::size_t>(p.sweep_buffer_size);
  return mp;
}

/// The image-set synchroniser: ExactTime (with a callback for the sets it gives up) or
/// ApproximateTime (~approximate_sync), resetting its queues when simulated time jumps back.
class StereoSync {
 public:
  using Image = sensor_msgs::Image;
  using Info = sensor_msgs::CameraInfo;
  /// A complete set, or (drop callback, exact sync only) an incomplete one given up (null parts).
  using SetCallback = boost::function<void(
      const sensor_msgs::ImageConstPtr&, const sensor_msgs::CameraInfoConstPtr&,
      const sensor_msgs::ImageConstPtr&, const sensor_msgs::CameraInfoConstPtr&)>;

  /// Connects to the four input filters (left image, left info, right image, right info).
  template <class LeftImage, class LeftInfo, class RightImage, class RightInfo>
  StereoSync(const NodeParams& params, LeftImage& left_image, LeftInfo& left_info,
             RightImage& right_image, RightInfo& right_info, const SetCallback& on_set,
             const SetCallback& on_drop) {
    // Both callbacks must be set. Bound, so that the synchroniser's extra (null) arguments drop.
    using boost::placeholders::_1;
    using boost::placeholders::_2;
    using boost::placeholders::_3;
    using boost::placeholders::_4;
    const auto set_cb = boost::bind<void>(on_set, _1, _2, _3, _4);
    const auto drop_cb = boost::bind<void>(on_drop, _1, _2, _3, _4);
    if (params.approximate_sync) {
      approx_ = std::make_shared<message_filters::Synchronizer<ApproxPolicy>>(
          ApproxPolicy(params.queue_size), left_image, left_info, right_image, right_info);
      approx_->setReset(true);  // clears its queues when simulated time jumps back
      approx_->registerCallback(set_cb);
    } else {
      exact_ = std::make_shared<message_filters::Synchronizer<ExactPolicy>>(
          ExactPolicy(params.queue_size), left_image, left_info, right_image, right_info);
      exact_->setReset(true);
      exact_->registerCallback(set_cb);
      exact_->registerDropCallback(drop_cb);
    }
  }

 private:
  using ExactPolicy = message_filters::sync_policies::ExactTime<Image, Info, Image, Info>;
  using ApproxPolicy = message_filters::sync_policies::ApproximateTime<Image, Info, Image, Info>;
  std::shared_ptr<message_filters::Synchronizer<ExactPolicy>> exact_;
  std::shared_ptr<message_filters::Synchronizer<ApproxPolicy>> approx_;
};

}  // namespace lidar_stereo_fusion
