// Publishing lidar_stereo_fusion/FusionStats (msg/FusionStats.msg).
//
// The worker fills a StatsReport (field by field the message) and src/ros/stats_publisher.cpp,
// which includes only the message, turns it into one, so the worker's sources stay free of the
// generated message. (The core's per-frame struct is lidar_stereo_fusion::FrameStats.)
#pragma once

#include <cstdint>
#include <string>

#include <ros/node_handle.h>
#include <ros/publisher.h>
#include <std_msgs/Header.h>

namespace lidar_stereo_fusion {

/// The fields of msg/FusionStats.msg (see there for units and meaning).
struct StatsReport {
  std::string method;
  float projection_ms = 0, upsampling_ms = 0, patchmatch_ms = 0, depth_ms = 0, total_ms = 0;
  float conversion_ms = 0, latency_ms = 0, sweep_time_offset = 0;
  int32_t points_in_cloud = 0, points_in_front = 0, points_projected = 0, points_removed = 0;
  int32_t rings = 0;
  bool rings_recovered = false;
  std::string ring_method;
  bool rings_plausible = true;
  float prior_coverage = 0, output_coverage = 0;
  uint32_t processed_frames = 0, dropped_frames = 0, unmatched_frames = 0, tf_failures = 0;
  uint32_t invalid_inputs = 0, out_of_order = 0, processing_errors = 0, rate_limited = 0;
};

/// Advertises `topic` (FusionStats) on `nh` with `status_cb` as connect and disconnect callback.
ros::Publisher advertiseStats(ros::NodeHandle& nh, const std::string& topic, uint32_t queue_size,
                              const ros::SubscriberStatusCallback& status_cb);

/// Publishes one FusionStats message.
void publishStats(const ros::Publisher& publisher, const std_msgs::Header& header,
                  const StatsReport& report);

}  // namespace lidar_stereo_fusion
