// The live fusion: the one worker class behind lidar_stereo_fusion/FusionNodelet and fusion_node.
//
// Topics (relative to the node handle `nh`, remappable; stereo_image_proc-style):
//   in:  left/image_rect_color, left/camera_info, right/image_rect_color, right/camera_info
//        (bgra8, rgba8, bgr8, rgb8 or mono8), velodyne_points (sensor_msgs/PointCloud2)
//   out: disparity (stereo_msgs/DisparityImage), depth + depth/camera_info (32FC1 [m], NaN = none),
//        points2 (PointCloud2 x, y, z, rgb), lidar_disparity (the up-sampled prior, 32FC1 [px],
//        0 = empty), disparity_image (the disparity as a plain 32FC1 image [px], 0 = none, for
//        RViz's Image display, which cannot show a DisparityImage), confidence (32FC1 in [0, 1],
//        the LiDAR prior's confidence, 0 = no prior; all 0 for methods without LiDAR), stats
//        (lidar_stereo_fusion/FusionStats), plus /diagnostics.
// Every output is in the left optical frame and stamped with the left image stamp.
//
// Threads: ROS callbacks only check, match and hand over (never block); one worker thread looks up
// TF, runs the core pipeline on the newest matched set and publishes. A set that is replaced by a
// newer one before the worker takes it is dropped and counted. Inputs are subscribed only while
// some output has a subscriber.
//
// Bad input never stops the node: every rejected message or skipped frame is counted (FusionStats,
// diagnostics) and logged at most once per 5 s per topic and kind of problem, naming both. When
// time restarts (the ROS clock or a stamp jumps back by more than 1 s: a bag played with --loop)
// the buffers are cleared instead of counting everything as out of order.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>
#include <dynamic_reconfigure/server.h>
#include <image_transport/image_transport.h>
#include <image_transport/subscriber_filter.h>
#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/approximate_time.h>
#include <message_filters/sync_policies/exact_time.h>
#include <message_filters/synchronizer.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <boost/optional.hpp>
#include <boost/thread/recursive_mutex.hpp>

#include "lidar_stereo_fusion/FusionConfig.h"
#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/ros/frame_matcher.h"

namespace lidar_stereo_fusion {

/// Parameters of the ROS layer (private namespace; defaults in config/fusion_node.yaml).
struct NodeParams {
  bool approximate_sync = false;  ///< ApproximateTime instead of ExactTime for the image set
  int queue_size = 5;             ///< synchroniser queue per topic
  double max_time_offset = 0.1;   ///< [s] largest |sweep stamp - image stamp|
  double max_sweep_wait = 0.3;    ///< [s] ROS time (sim time aware) a set waits for a later sweep
  int sweep_buffer_size = 10;     ///< recent sweeps kept for matching
  double tf_timeout = 0.05;       ///< [s] LiDAR -> camera TF lookup timeout (worker thread)
  int num_rings = 64;             ///< rings recovered by elevation for clouds without `ring`
  int cloud_stride = 1;           ///< points2 keeps every k-th pixel in rows and columns
  double max_output_depth = 0.0;  ///< [m] depth / points2 beyond this are empty (0 = no limit)
  /// [Hz] image sets stamped closer than 0.9 / max_rate after the last accepted one are dropped on
  /// arrival, counted (FusionStats.rate_limited) and not warned about. 0 = no limit.
  double max_rate = 0.0;
  /// Nice increment of the worker thread (and so of the OpenMP threads it starts): the pipeline
  /// uses every core, and ROS callbacks, nodelet bond heartbeats and drivers in the same machine
  /// must still be served on time. 0 = same priority as the callbacks.
  int worker_nice = 10;
  double diag_min_rate = 1.0;     ///< [Hz] diagnostics: lowest acceptable output rate
  double diag_max_rate = 100.0;   ///< [Hz] diagnostics: highest acceptable output rate
  double diag_max_latency = 2.0;  ///< [s] diagnostics: largest acceptable stamp -> publish delay

  /// Reads the parameters present under `pnh`; a wrong type or impossible value is logged as an
  /// error naming the parameter and the default is kept.
  static NodeParams read(const ros::NodeHandle& pnh);
};

class FusionWorker {
 public:
  /// `nh`: topics; `pnh`: parameters; `name`: used in log messages (the nodelet / node name).
  FusionWorker(const ros::NodeHandle& nh, const ros::NodeHandle& pnh, const std::string& name);
  ~FusionWorker();
  FusionWorker(const FusionWorker&) = delete;
  FusionWorker& operator=(const FusionWorker&) = delete;

 private:
  using ImageConstPtr = sensor_msgs::ImageConstPtr;
  using InfoConstPtr = sensor_msgs::CameraInfoConstPtr;
  using CloudConstPtr = sensor_msgs::PointCloud2ConstPtr;
  using Image = sensor_msgs::Image;
  using Info = sensor_msgs::CameraInfo;
  using ExactPolicy = message_filters::sync_policies::ExactTime<Image, Info, Image, Info>;
  using ApproxPolicy = message_filters::sync_policies::ApproximateTime<Image, Info, Image, Info>;
  using ExactSync = message_filters::Synchronizer<ExactPolicy>;
  using ApproxSync = message_filters::Synchronizer<ApproxPolicy>;
  using Clock = std::chrono::steady_clock;

  struct ImageSet {
    ImageConstPtr left, right;
    InfoConstPtr left_info, right_info;
    ros::Time arrival_ros;           ///< ROS time when the set was complete
    Clock::time_point arrival_wall;  ///< the same in wall time (latency across a bag loop)
  };
  using Matcher = FrameMatcher<ImageSet, CloudConstPtr>;
  using Match = Matcher::Match;

  /// Cumulative counters (also published in FusionStats).
  struct Counters {
    std::atomic<uint32_t> processed{0}, dropped{0}, unmatched{0}, tf_failures{0}, invalid{0},
        out_of_order{0}, errors{0}, rate_limited{0};
  };

  // Setup and lazy subscription.
  void advertise();
  void connectCb();
  void subscribe();
  void unsubscribe();

  // Callbacks: check, match, hand over. Never block.
  void imageCb(const ImageConstPtr& left, const InfoConstPtr& left_info, const ImageConstPtr& right,
               const InfoConstPtr& right_info);
  void syncDropCb(const ImageConstPtr& left, const InfoConstPtr& left_info,
                  const ImageConstPtr& right, const InfoConstPtr& right_info);
  void cloudCb(const CloudConstPtr& cloud);
  void reconfigureCb(FusionConfig& config, uint32_t level);
  bool checkImageSet(const ImageSet& set);
  void handleEvents(Matcher::Events& events, const std::string& topic, const ros::Time& stamp);
  void detectClockJump();

  // Worker thread.
  void workerLoop();
  void processMatch(const Match& match, FusionPipeline& pipeline);
  void publishOutputs(const Match& match, const StereoCamera& camera, const cv::Mat& left_image,
                      const FusionResult& result, const FusionParams& params, int cloud_points,
                      const RingRecovery& rings, double conversion_ms);

  // Diagnostics.
  void diagnoseOutput(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void diagnoseProcessing(diagnostic_updater::DiagnosticStatusWrapper& stat);

  /// Logs `text` at most once per kThrottlePeriod for each (`topic`, `kind`) -- the kind of
  /// problem, a fixed word, never text that varies -- so that one problem does not hide another
  /// and the key set stays bounded.
  enum class Level { kInfo, kWarn, kError };
  void logThrottled(Level level, const std::string& topic, const std::string& kind,
                    const std::string& text);
  void warnThrottled(const std::string& topic, const std::string& kind, const std::string& text) {
    logThrottled(Level::kWarn, topic, kind, text);
  }
  std::string topicName(const std::string& relative) const;

  ros::NodeHandle nh_, pnh_;
  std::string name_;
  NodeParams node_params_;

  // Inputs.
  std::shared_ptr<image_transport::ImageTransport> it_;
  image_transport::SubscriberFilter sub_left_image_, sub_right_image_;
  message_filters::Subscriber<Info> sub_left_info_, sub_right_info_;
  std::shared_ptr<ExactSync> exact_sync_;
  std::shared_ptr<ApproxSync> approx_sync_;
  ros::Subscriber sub_cloud_;
  std::mutex connect_mutex_;  ///< guards (un)subscription and subscribed_
  bool subscribed_ = false;

  // Outputs.
  ros::Publisher pub_disparity_, pub_points_, pub_stats_;
  // depth + depth/camera_info: not an image_transport CameraPublisher, which would put the info
  // next to the image (camera_info), not under it.
  image_transport::Publisher pub_depth_;
  ros::Publisher pub_depth_info_;
  image_transport::Publisher pub_lidar_disparity_, pub_disparity_image_, pub_confidence_;

  // TF (own listener thread).
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;

  // Matching and hand-over to the worker (data_mutex_).
  std::mutex data_mutex_;
  std::condition_variable job_cv_;
  Matcher matcher_;
  boost::optional<Match> next_job_;
  bool stop_ = false;
  ros::Time last_clock_;
  ros::Time last_accepted_stamp_;  ///< of the last image set let through by max_rate

  // Parameters (params_mutex_); the worker applies pending ones before its next frame.
  std::mutex params_mutex_;
  FusionParams params_;
  bool params_changed_ = false;
  boost::recursive_mutex reconfigure_mutex_;  ///< the server's (so updateConfig() cannot deadlock)
  std::unique_ptr<dynamic_reconfigure::Server<FusionConfig>> reconfigure_server_;

  Counters counters_;

  // Diagnostics.
  diagnostic_updater::Updater updater_;
  diagnostic_updater::FrequencyStatus output_frequency_;
  diagnostic_updater::TimeStampStatus output_stamps_;
  ros::Timer diag_timer_;
  std::mutex diag_mutex_;
  std::deque<double> recent_total_ms_, recent_latency_ms_;
  uint32_t diag_last_problems_ = 0;

  std::mutex log_mutex_;
  std::map<std::string, ros::WallTime> last_log_;  ///< (topic, kind) -> last time logged

  std::thread worker_;  ///< last member: started after everything else exists
};

}  // namespace lidar_stereo_fusion
