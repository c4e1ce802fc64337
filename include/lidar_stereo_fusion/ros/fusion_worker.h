// The live fusion behind lidar_stereo_fusion/FusionNodelet and fusion_node, in three parts along
// the data path, each with one lock and its own unit tests (test/ros/test_node_parts.cpp):
//   InputGate (input_gate.h)           subscription, checks, ~max_rate, sweep pairing in ROS time
//   FusionWorker (this file)           TF, the frame path (frame_input.h), the core pipeline,
//                                      parameters
//   OutputPublisher (output_publisher.h)  messages, FusionStats, diagnostics, lazy subscription
// Inputs (relative to `nh`, remappable; stereo_image_proc-style): left/image_rect_color,
// left/camera_info, right/image_rect_color, right/camera_info (bgra8, rgba8, bgr8, rgb8 or mono8),
// velodyne_points (sensor_msgs/PointCloud2). Outputs: see output_publisher.h.
//
// Threads: ROS callbacks only check, match and hand over (never block); one worker thread looks up
// TF, runs the core pipeline on the newest matched set and publishes. Bad input never stops the
// node: every rejected message or skipped frame is counted (FusionStats, diagnostics) and logged
// at most once per 5 s per topic and kind of problem, naming both. When time restarts (the ROS
// clock or a stamp jumps back by more than 1 s: a bag played with --loop) the buffers are cleared
// instead of counting everything as out of order.
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <dynamic_reconfigure/server.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <boost/thread/recursive_mutex.hpp>

#include "lidar_stereo_fusion/FusionConfig.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/ros/frame_input.h"
#include "lidar_stereo_fusion/ros/input_gate.h"
#include "lidar_stereo_fusion/ros/node_support.h"
#include "lidar_stereo_fusion/ros/output_publisher.h"
#include "lidar_stereo_fusion/ros/rate_governor.h"

namespace lidar_stereo_fusion {

class FusionWorker {
 public:
  /// `nh`: topics; `pnh`: parameters; `name`: used in log messages (the nodelet / node name).
  FusionWorker(const ros::NodeHandle& nh, const ros::NodeHandle& pnh, const std::string& name);
  ~FusionWorker();
  FusionWorker(const FusionWorker&) = delete;
  FusionWorker& operator=(const FusionWorker&) = delete;

 private:
  void reconfigureCb(FusionConfig& config, uint32_t level);
  void workerLoop();
  /// The frame path of one matched set: extrinsics from TF, prepareFusionInput (frame_input.h),
  /// the core pipeline, the outputs.
  void processMatch(const InputMatch& match, FusionPipeline& pipeline);
  /// keep_rate: the governor's view of the frame just processed (`busy_ms` the worker's time on
  /// it); applies and reports a change of the search effort.
  void keepRate(RateGovernor& governor, FusionPipeline& pipeline, double busy_ms);
  /// LiDAR -> camera at extrinsicsStamp(), waiting up to ~tf_timeout. On a failure: counted,
  /// warned and false (the frame is skipped).
  bool lookupExtrinsics(const InputMatch& match, Eigen::Isometry3d& T_cam_lidar);
  /// EgoMotionTf::wait of the live node: up to ~tf_timeout for `lidar_frame` in `fixed_frame` at
  /// `latest`; throws tf2::TransformException naming the frames, the stamp and the timeout.
  void waitForTf(const std::string& fixed_frame, const std::string& lidar_frame,
                 const ros::Time& latest);
  /// Counts and logs what the frame path said: its notes (throttled; the mixed-encoding note once
  /// per pair of encodings), an ego-motion failure, a rejection.
  void reportFrame(const PreparedFrame& frame);
  std::string topicName(const std::string& relative) const { return nh_.resolveName(relative); }

  ros::NodeHandle nh_, pnh_;
  std::string name_;
  NodeParams node_params_;  ///< as read at start-up (the synchroniser, threads and log use them)
  NodeParams frame_node_;   ///< in force for the frame being processed (worker thread only)
  ThrottledLog log_;
  Counters counters_;
  InputGate gate_;
  OutputPublisher outputs_;
  std::string mixed_encodings_said_;  ///< the last mixed-encoding note logged (worker thread)
  uint32_t governor_dropped_ = 0;     ///< counters_.dropped when the governor last looked

  // TF (own listener thread).
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;

  // Parameters: the worker applies pending ones before its next frame. One lock (params_mutex_);
  // the dynamic_reconfigure server needs its own (recursive, so updateConfig() cannot deadlock).
  std::mutex params_mutex_;
  FusionParams params_;
  NodeParams live_node_;  ///< node_params_ with the live rows dynamic_reconfigure changed
  bool params_changed_ = false;
  boost::recursive_mutex reconfigure_mutex_;
  std::unique_ptr<dynamic_reconfigure::Server<FusionConfig>> reconfigure_server_;

  std::thread worker_;  ///< last member: started after everything else exists
};

}  // namespace lidar_stereo_fusion
