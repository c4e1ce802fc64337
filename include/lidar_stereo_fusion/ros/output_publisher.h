// The output publisher of the live node: advertises the outputs, subscribes the input gate while
// any output has a subscriber (lazy subscription), turns a core result into messages, builds
// FusionStats once from the core's FrameStats and a snapshot of the counters, and reports
// diagnostics (output rate, stamps, processing time).
//
// Outputs (relative to the node handle): disparity (stereo_msgs/DisparityImage), depth/image_rect +
// depth/camera_info (32FC1 [m], NaN = none), points2 (x, y, z, rgb, organised H x W, NaN = none),
// depth/image_color (bgr8, the depth coloured with a scale bar in metres, for RViz),
// lidar_disparity (the up-sampled prior, 32FC1 [px], 0 = empty), disparity_image (32FC1 [px], 0 =
// none, for RViz), confidence (32FC1 in [0, 1], the prior's confidence, 0 = no prior; all 0 for
// methods without LiDAR), stats (lidar_stereo_fusion/FusionStats), plus /diagnostics. Every output
// is in the left optical frame and stamped with the left image stamp.
//
// One lock (mutex_): the subscription state (serialising the gate's subscribe / unsubscribe) and
// the windows of recent processing times.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>
#include <image_transport/image_transport.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <stereo_msgs/DisparityImage.h>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/FusionStats.h"
#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/ros/frame_input.h"
#include "lidar_stereo_fusion/ros/input_gate.h"
#include "lidar_stereo_fusion/ros/node_support.h"

namespace lidar_stereo_fusion {

/// Latency [ms] from the image stamp to `publish_time` (ROS time). When ROS time restarted after
/// the set arrived (`restarted`, or publish_time before the arrival: a bag loop), the latency at
/// arrival (at least 0) plus the wall time since: a loop cannot make it negative.
double latencyMs(const ros::Time& publish_time, const ros::Time& image_stamp,
                 const ros::Time& arrival_ros, double wall_ms_since_arrival, bool restarted);

/// FusionStats of one frame: the core's FrameStats, the frame report, the latency and the
/// counters as they are now.
FusionStatsPtr makeStatsMsg(const std_msgs::Header& header, const FrameStats& stats,
                            const FrameReport& report, double total_conversion_ms,
                            double latency_ms, double sweep_time_offset,
                            const CounterSnapshot& counters);

/// The depth [m] the node publishes (depth/image_rect, points2; 0 = none) for a core result: the
/// pipeline's, or its disparity's, with depths beyond `max_output_depth` [m] (> 0) emptied.
/// Shared with bag_runner.
cv::Mat1f outputDepth(const FusionResult& result, const StereoCamera& camera,
                      double max_output_depth);

class OutputPublisher {
 public:
  OutputPublisher(const ros::NodeHandle& nh, const ros::NodeHandle& pnh, const std::string& name,
                  const NodeParams& params, Counters& counters, InputGate& gate);
  ~OutputPublisher();
  OutputPublisher(const OutputPublisher&) = delete;
  OutputPublisher& operator=(const OutputPublisher&) = delete;

  /// Advertises the outputs; from then on subscribers make the gate subscribe. Call last.
  void advertise();
  /// Unsubscribes the gate for good (shutdown).
  void shutdown();
  /// Takes the live output parameters (cloud_stride, max_output_depth, depth_color_max) from
  /// `params`; call from the thread that publishes, between frames.
  void setLiveParams(const NodeParams& params);
  /// The search effort in force for the processing diagnostics (keep_rate, rate_governor.h):
  /// `reduced` (a warning while it lasts) and what it is.
  void setSearchEffort(bool reduced, const std::string& text);
  /// Publishes the outputs of one frame to the outputs that have subscribers.
  void publish(const InputMatch& match, const StereoCamera& camera, const cv::Mat& left_image,
               const FusionResult& result, const FusionParams& params, const FrameReport& report);

 private:
  /// The messages of one frame, each made only when its output has a subscriber.
  struct Messages {
    stereo_msgs::DisparityImagePtr disparity;
    sensor_msgs::ImagePtr disparity_image, disparity_color, depth, depth_color, prior, confidence;
    sensor_msgs::CameraInfoPtr depth_info;
    sensor_msgs::PointCloud2Ptr points;
  };
  /// disparity, disparity_image, disparity_image_color.
  void makeDisparityMessages(const FusionResult& result, const StereoCamera& camera,
                             const FusionParams& params, const std_msgs::Header& header,
                             Messages& out) const;
  /// depth/image_rect + depth/camera_info, depth/image_color, points2 (all from outputDepth).
  void makeDepthMessages(const FusionResult& result, const StereoCamera& camera,
                         const cv::Mat& left_image, const InputMatch& match, Messages& out) const;
  /// lidar_disparity, confidence.
  void makeLidarMessages(const FusionResult& result, const StereoCamera& camera,
                         const std_msgs::Header& header, Messages& out) const;
  void publishMessages(const Messages& messages);
  /// The frame in the output diagnostics: rate, stamp, processing time and latency [ms].
  void recordFrame(const ros::Time& image_stamp, double total_ms, double latency_ms);
  void connectCb();
  void diagnoseOutput(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void diagnoseProcessing(diagnostic_updater::DiagnosticStatusWrapper& stat);

  ros::NodeHandle nh_, pnh_;
  NodeParams params_;
  Counters& counters_;
  InputGate& gate_;

  std::shared_ptr<image_transport::ImageTransport> it_;
  ros::Publisher pub_disparity_, pub_points_, pub_stats_;
  image_transport::CameraPublisher pub_depth_;  ///< depth/image_rect + depth/camera_info
  image_transport::Publisher pub_depth_color_;  ///< depth/image_color
  image_transport::Publisher pub_lidar_disparity_, pub_disparity_image_, pub_disparity_color_,
      pub_confidence_;

  diagnostic_updater::Updater updater_;
  diagnostic_updater::FrequencyStatus output_frequency_;
  diagnostic_updater::TimeStampStatus output_stamps_;
  ros::WallTimer diag_timer_;

  std::mutex mutex_;  ///< the one lock
  bool shut_down_ = false;
  std::deque<double> recent_total_ms_, recent_latency_ms_;
  uint32_t diag_last_problems_ = 0;
  bool effort_reduced_ = false;
  std::string effort_text_ = "as configured";
  uint32_t diag_clock_epoch_ = 0;  ///< diagnostics thread only
};

}  // namespace lidar_stereo_fusion
