// measure_fusion: end-to-end latency and sustained output rate of a running fusion nodelet.
//
// Subscribes to every output of the fusion in namespace ~ns (default /fusion), so that all of them
// are computed (~outputs "all"), or only to depth/image_rect and its camera_info, as a consumer of
// depth would (~outputs "depth"). Ignores ~warmup seconds, then records ~duration seconds of stats
// and prints: output rate, latency image stamp -> publish (from FusionStats) and image stamp ->
// receipt here, core processing time, the ROS conversions, the rest of the latency (transport and
// the wait for the worker), and the frames dropped / unmatched meanwhile. Exits when done.
#include <algorithm>
#include <cstdio>
#include <mutex>
#include <numeric>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <stereo_msgs/DisparityImage.h>

#include "lidar_stereo_fusion/FusionStats.h"

namespace {

struct Sample {
  double receipt;        ///< [s] wall
  double latency_ms;     ///< stamp -> publish, from FusionStats
  double receipt_ms;     ///< stamp -> receipt here
  double total_ms;       ///< core pipeline
  double conversion_ms;  ///< ROS conversions in and out (not in total_ms)
  uint32_t dropped, unmatched, processed;
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * (v.size() - 1) + 0.5))];
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "measure_fusion");
  ros::NodeHandle nh, pnh("~");
  const std::string ns = pnh.param<std::string>("ns", "/fusion");
  const double warmup = pnh.param("warmup", 5.0);
  const double duration = pnh.param("duration", 30.0);

  std::mutex mutex;
  std::vector<Sample> samples;
  int skipped = 0;
  const ros::WallTime start = ros::WallTime::now();
  auto stats_sub = nh.subscribe<lidar_stereo_fusion::FusionStats>(
      ns + "/stats", 50, [&](const lidar_stereo_fusion::FusionStatsConstPtr& s) {
        const ros::WallTime now = ros::WallTime::now();
        if ((now - start).toSec() < warmup) return;
        std::lock_guard<std::mutex> lock(mutex);
        if (s->latency_ms < 0.0) {  // simulated time jumped back (bag loop) meanwhile
          ++skipped;
          return;
        }
        samples.push_back({now.toSec(), s->latency_ms,
                           (ros::Time::now() - s->header.stamp).toSec() * 1e3, s->total_ms,
                           s->conversion_ms, s->dropped_frames, s->unmatched_frames,
                           s->processed_frames});
      });
  // Keep the outputs computed: every one (~outputs "all"), or a consumer's (e.g. "depth").
  const std::string outputs = pnh.param<std::string>("outputs", "all");
  if (outputs != "all" && outputs != "depth") {
    std::fprintf(stderr, "measure_fusion: ~outputs must be all or depth, got '%s'\n",
                 outputs.c_str());
    return 2;
  }
  std::vector<ros::Subscriber> keep;
  keep.push_back(nh.subscribe<sensor_msgs::CameraInfo>(
      ns + "/depth/camera_info", 1, +[](const sensor_msgs::CameraInfoConstPtr&) {}));
  keep.push_back(nh.subscribe<sensor_msgs::Image>(
      ns + "/depth/image_rect", 1, +[](const sensor_msgs::ImageConstPtr&) {}));
  if (outputs == "all") {
    keep.push_back(nh.subscribe<stereo_msgs::DisparityImage>(
        ns + "/disparity", 1, +[](const stereo_msgs::DisparityImageConstPtr&) {}));
    keep.push_back(nh.subscribe<sensor_msgs::PointCloud2>(
        ns + "/points2", 1, +[](const sensor_msgs::PointCloud2ConstPtr&) {}));
    for (const char* image : {"/lidar_disparity", "/disparity_image"}) {
      keep.push_back(nh.subscribe<sensor_msgs::Image>(
          ns + image, 1, +[](const sensor_msgs::ImageConstPtr&) {}));
    }
  }

  // The measurement ends when its window does (or ROS shuts down first).
  const ros::WallTimer end = nh.createWallTimer(
      ros::WallDuration(warmup + duration) - (ros::WallTime::now() - start),
      [](const ros::WallTimerEvent&) { ros::shutdown(); }, /*oneshot=*/true);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  ros::waitForShutdown();
  std::lock_guard<std::mutex> lock(mutex);
  if (samples.size() < 2) {
    std::printf("measure_fusion: %zu frames in %.0f s: no rate\n", samples.size(), duration);
    return 1;
  }
  std::vector<double> latency, receipt, total, conversion, waited;
  for (const auto& s : samples) {
    latency.push_back(s.latency_ms);
    receipt.push_back(s.receipt_ms);
    total.push_back(s.total_ms);
    conversion.push_back(s.conversion_ms);
    // The rest of the latency: transport in, the set's wait for the worker, publishing.
    waited.push_back(s.latency_ms - s.total_ms - s.conversion_ms);
  }
  const auto mean = [](const std::vector<double>& v) {
    return std::accumulate(v.begin(), v.end(), 0.0) / v.size();
  };
  const double span = samples.back().receipt - samples.front().receipt;
  std::printf(
      "measure_fusion: %zu frames in %.1f s -> %.2f Hz sustained output\n"
      "  latency image stamp -> publish [ms]: mean %.0f  median %.0f  p95 %.0f  max %.0f\n"
      "  latency image stamp -> receipt [ms]: mean %.0f  median %.0f  p95 %.0f\n"
      "  core pipeline [ms]:                  mean %.0f  median %.0f  p95 %.0f  max %.0f\n"
      "  ROS conversions in + out [ms]:       mean %.0f  p95 %.0f\n"
      "  rest (transport, wait for the worker) [ms]: mean %.0f  p95 %.0f\n"
      "  meanwhile: %u sets dropped (newer one waiting), %u unmatched; %d frames across a time "
      "jump "
      "not counted\n",
      samples.size(), span, (samples.size() - 1) / span, mean(latency), percentile(latency, 0.5),
      percentile(latency, 0.95), percentile(latency, 1.0), mean(receipt), percentile(receipt, 0.5),
      percentile(receipt, 0.95), mean(total), percentile(total, 0.5), percentile(total, 0.95),
      percentile(total, 1.0), mean(conversion), percentile(conversion, 0.95), mean(waited),
      percentile(waited, 0.95), samples.back().dropped - samples.front().dropped,
      samples.back().unmatched - samples.front().unmatched, skipped);
  return 0;
}
