// The input gate of the live node: subscriptions (made and dropped by the output publisher, which
// knows when anyone listens), the checks of every message where it enters, ~max_rate, and the
// pairing of image sets with sweeps in ROS time (FrameMatcher). It hands the newest matched set to
// the worker and drops (and counts) older ones: never a backlog. A set that waited for the busy
// worker may be exchanged for the next one if that is due within ~fresh_wait (FreshWait).
//
// One lock (mutex_): the matcher, the hand-over slot, the clock and rate state. Subscribing and
// unsubscribing happen without it (a subscription's shutdown waits for its running callbacks,
// which take it) and are serialised by the caller.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>

#include <image_transport/image_transport.h>
#include <message_filters/subscriber.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <boost/optional.hpp>

#include "lidar_stereo_fusion/ros/frame_matcher.h"
#include "lidar_stereo_fusion/ros/fresh_wait.h"
#include "lidar_stereo_fusion/ros/image_input.h"
#include "lidar_stereo_fusion/ros/input_watch.h"
#include "lidar_stereo_fusion/ros/node_support.h"
#include "lidar_stereo_fusion/ros/stereo_order.h"
#include "lidar_stereo_fusion/ros/stereo_sync.h"

namespace lidar_stereo_fusion {

/// ~max_rate: accepts a stamp when it is at least 0.9 / max_rate after the last accepted one (or
/// before it: time went back, the matcher decides). max_rate 0 accepts everything. Not locked.
class RateLimiter {
 public:
  explicit RateLimiter(double max_rate) : max_rate_(max_rate) {}
  bool accept(const ros::Time& stamp);

 private:
  double max_rate_;
  ros::Time last_;
};

class InputGate {
 public:
  InputGate(const ros::NodeHandle& nh, const ros::NodeHandle& pnh, const NodeParams& params,
            Counters& counters, ThrottledLog& log);
  ~InputGate();
  InputGate(const InputGate&) = delete;
  InputGate& operator=(const InputGate&) = delete;

  /// Subscribe to / drop the inputs. Not thread-safe against each other: the caller serialises.
  /// Dropping forgets (and counts) every set still waiting.
  void subscribe();
  void unsubscribe();
  bool subscribed() const { return subscribed_; }

  /// The newest matched set, waiting up to `timeout` for one; first decides the sets that waited
  /// ~max_sweep_wait of ROS time. A set that was already waiting may be exchanged for the next
  /// one, if that is due within ~fresh_wait (FreshWait). None on timeout or after stop().
  boost::optional<InputMatch> next(std::chrono::milliseconds timeout);
  void stop();
  bool stopped() const { return stopped_; }
  /// Incremented whenever ROS time or the stamps restart (a bag loop): a set that arrived in an
  /// earlier epoch cannot measure its latency in ROS time.
  uint32_t clockEpoch() const { return clock_epoch_; }
  /// [s] The time between matched sets (FreshWait's median interval); 0 while not known.
  double inputPeriod();
  /// The input topics (resolved, as subscribed), comma-separated.
  std::string inputTopics() const;
  /// How the image inputs are subscribed (~image_transport and the installed plugins).
  const TransportChoice& transport() const { return transport_; }

 private:
  void watchInputs();  ///< the constructor's last step: the input watch's callbacks and timer
  using Image = sensor_msgs::Image;
  using Info = sensor_msgs::CameraInfo;

  void imageCb(const sensor_msgs::ImageConstPtr& left, const sensor_msgs::CameraInfoConstPtr& li,
               const sensor_msgs::ImageConstPtr& right, const sensor_msgs::CameraInfoConstPtr& ri);
  void syncDropCb(const sensor_msgs::ImageConstPtr& left, const sensor_msgs::CameraInfoConstPtr& li,
                  const sensor_msgs::ImageConstPtr& right,
                  const sensor_msgs::CameraInfoConstPtr& ri);
  void cloudCb(const sensor_msgs::PointCloud2ConstPtr& cloud);
  void reject(const Rejection& r, const ros::Time& stamp, const char* what_skipped);
  /// The first image sets: is the pair the right way round (StereoOrderWatch; warns once)?
  void checkStereoOrder(const ImageSet& set);
  // With mutex_ held:
  void handleEvents(InputMatcher::Events& events, const std::string& topic, const ros::Time& stamp);
  void detectClockJump();
  /// Now on the watch's clock: wall time, or ROS time under /use_sim_time (as a time point).
  static InputWatch::Clock::time_point watchNow();
  void restarted(const ros::Time& now);
  /// Whether the set stamped `stamp` was lost to a restart of time (a bag loop), not to the rig.
  bool lostToRestart(const ros::Time& stamp) const;
  /// Whether a sweep refused lately (reject) could have been the one for the set at `image_stamp`.
  bool sweepRefusedNear(const ros::Time& image_stamp) const;
  /// Why no sweep matched the image set at `image_stamp` (unmatched, or `waited` for a later one).
  std::string noSweepText(const ros::Time& image_stamp, bool waited) const;
  void waitForFresher(std::unique_lock<std::mutex>& lock);
  std::string topicName(const std::string& relative) const;

  ros::NodeHandle nh_, pnh_;
  NodeParams params_;
  Counters& counters_;
  ThrottledLog& log_;
  TransportChoice transport_;  ///< before watch_, which names the topics it chose

  std::shared_ptr<image_transport::ImageTransport> it_;
  ImageInput sub_left_image_, sub_right_image_;
  message_filters::Subscriber<Info> sub_left_info_, sub_right_info_;
  std::unique_ptr<StereoSync> sync_;  ///< the image-set synchroniser (shared with bag_runner)
  ros::Subscriber sub_cloud_;
  std::atomic<bool> subscribed_{false};
  InputWatch watch_;  ///< names silent inputs (its own lock)
  ros::WallTimer watch_timer_;
  std::atomic<bool> watch_clock_started_{false};  ///< under sim time: the watch saw a clock
  std::mutex order_mutex_;                        ///< order_watch_ (tried, never waited for)
  StereoOrderWatch order_watch_;

  std::mutex mutex_;  ///< the one lock
  std::condition_variable ready_cv_;
  InputMatcher matcher_;
  boost::optional<InputMatch> next_;
  uint64_t ready_count_ = 0;  ///< sets handed to next_ so far
  RateLimiter rate_;
  FreshWait fresh_;
  ros::Time last_clock_;
  /// ROS time of the last restart of time (a bag loop): for a moment after it, lost sets are not
  /// warned about with advice meant for a misconfigured rig (lostToRestart).
  ros::Time restart_time_;
  /// The last sweep refused (reject), so that a set left without one says why.
  ros::Time refused_sweep_stamp_;
  std::string refused_sweep_problem_, refused_sweep_kind_;
  bool stop_ = false;
  std::atomic<bool> stopped_{false};
  std::atomic<uint32_t> clock_epoch_{0};
};

}  // namespace lidar_stereo_fusion
