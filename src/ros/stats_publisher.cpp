// Includes the generated FusionStats message and nothing of the core (see stats_publisher.h).
#include "lidar_stereo_fusion/ros/stats_publisher.h"

#include <boost/make_shared.hpp>

#include "lidar_stereo_fusion/FusionStats.h"

namespace lidar_stereo_fusion {

ros::Publisher advertiseStats(ros::NodeHandle& nh, const std::string& topic, uint32_t queue_size,
                              const ros::SubscriberStatusCallback& status_cb) {
  return nh.advertise<lidar_stereo_fusion::FusionStats>(topic, queue_size, status_cb, status_cb);
}

void publishStats(const ros::Publisher& publisher, const std_msgs::Header& header,
                  const StatsReport& r) {
  auto msg = boost::make_shared<lidar_stereo_fusion::FusionStats>();
  msg->header = header;
  msg->method = r.method;
  msg->projection_ms = r.projection_ms;
  msg->upsampling_ms = r.upsampling_ms;
  msg->patchmatch_ms = r.patchmatch_ms;
  msg->depth_ms = r.depth_ms;
  msg->total_ms = r.total_ms;
  msg->conversion_ms = r.conversion_ms;
  msg->latency_ms = r.latency_ms;
  msg->sweep_time_offset = r.sweep_time_offset;
  msg->points_in_cloud = r.points_in_cloud;
  msg->points_in_front = r.points_in_front;
  msg->points_projected = r.points_projected;
  msg->points_removed = r.points_removed;
  msg->rings = r.rings;
  msg->rings_recovered = r.rings_recovered;
  msg->ring_method = r.ring_method;
  msg->rings_plausible = r.rings_plausible;
  msg->prior_coverage = r.prior_coverage;
  msg->output_coverage = r.output_coverage;
  msg->processed_frames = r.processed_frames;
  msg->dropped_frames = r.dropped_frames;
  msg->unmatched_frames = r.unmatched_frames;
  msg->tf_failures = r.tf_failures;
  msg->invalid_inputs = r.invalid_inputs;
  msg->out_of_order = r.out_of_order;
  msg->processing_errors = r.processing_errors;
  msg->rate_limited = r.rate_limited;
  publisher.publish(msg);
}

}  // namespace lidar_stereo_fusion
