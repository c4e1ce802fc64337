#include "lidar_stereo_fusion/ros/output_publisher.h"

#include <algorithm>
#include <numeric>

#include <boost/make_shared.hpp>

#include "lidar_stereo_fusion/core/depth.h"
#include "lidar_stereo_fusion/io/visualization.h"
#include "lidar_stereo_fusion/ros/conversions.h"

namespace lidar_stereo_fusion {

namespace {

constexpr std::size_t kDiagWindow = 30;  ///< frames averaged in the processing diagnostics

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

double latencyMs(const ros::Time& publish_time, const ros::Time& image_stamp,
                 const ros::Time& arrival_ros, double wall_ms_since_arrival, bool restarted) {
  if (!restarted && publish_time >= arrival_ros) return (publish_time - image_stamp).toSec() * 1e3;
  // The set may itself have arrived after the restart (its stamp from the old loop, the arrival
  // time from the new one): then the transport part is unknown, and 0 is the honest lower bound.
  return std::max(0.0, (arrival_ros - image_stamp).toSec() * 1e3) + wall_ms_since_arrival;
}

FusionStatsPtr makeStatsMsg(const std_msgs::Header& header, const FrameStats& s,
                            const FrameReport& report, double total_conversion_ms,
                            double latency_ms, double sweep_time_offset, const CounterSnapshot& c) {
  auto msg = boost::make_shared<FusionStats>();
  msg->header = header;
  msg->method = report.method;
  msg->projection_ms = static_cast<float>(s.projection_ms);
  msg->upsampling_ms = static_cast<float>(s.upsampling_ms);
  msg->patchmatch_ms = static_cast<float>(s.patchmatch_ms);
  msg->depth_ms = static_cast<float>(s.depth_ms);
  msg->total_ms = static_cast<float>(s.total_ms);
  msg->conversion_ms = static_cast<float>(total_conversion_ms);
  msg->latency_ms = static_cast<float>(latency_ms);
  msg->sweep_time_offset = static_cast<float>(sweep_time_offset);
  msg->points_in_cloud = report.cloud_points;
  msg->points_invalid = report.invalid_points;
  msg->points_in_front = s.points_in_front;
  msg->points_projected = s.points_projected;
  msg->points_removed = s.points_removed;
  msg->rings = report.rings.rings;
  msg->rings_recovered = report.rings.source != RingSource::kField;
  msg->ring_method = ringSourceName(report.rings.source);
  msg->rings_plausible = report.rings.plausible;
  msg->point_time_field = report.point_time_field;
  msg->points_bad_time = report.bad_times;
  msg->motion_compensated = report.motion_compensated;
  msg->motion_ms = static_cast<float>(report.motion_ms);
  msg->prior_coverage = static_cast<float>(s.prior_coverage);
  msg->output_coverage = static_cast<float>(s.output_coverage);
  msg->processed_frames = c.processed;
  msg->dropped_frames = c.dropped;
  msg->unmatched_frames = c.unmatched;
  msg->tf_failures = c.tf_failures;
  msg->invalid_inputs = c.invalid;
  msg->out_of_order = c.out_of_order;
  msg->processing_errors = c.errors;
  msg->rate_limited = c.rate_limited;
  msg->motion_failures = c.motion_failures;
  return msg;
}

OutputPublisher::OutputPublisher(const ros::NodeHandle& nh, const ros::NodeHandle& pnh,
                                 const std::string& name, const NodeParams& params,
                                 Counters& counters, InputGate& gate)
    : nh_(nh),
      pnh_(pnh),
      params_(params),
      counters_(counters),
      gate_(gate),
      it_(std::make_shared<image_transport::ImageTransport>(nh)),
      updater_(nh, pnh, name),
      output_frequency_(diagnostic_updater::FrequencyStatusParam(&params_.diag_min_rate,
                                                                 &params_.diag_max_rate, 0.1, 10)),
      output_stamps_(diagnostic_updater::TimeStampStatusParam(-1.0, params_.diag_max_latency)) {
  updater_.setHardwareID("none");
  updater_.add("output", this, &OutputPublisher::diagnoseOutput);
  updater_.add("processing", this, &OutputPublisher::diagnoseProcessing);
  // A wall-clock timer and force_update(): Updater::update() and ROS timers wait for ROS time to
  // pass the next period, which after a bag loop (simulated time jumps back) takes a whole loop.
  diag_timer_ = nh_.createWallTimer(
      ros::WallDuration(1.0), [this](const ros::WallTimerEvent&) { updater_.force_update(); });
}

OutputPublisher::~OutputPublisher() { shutdown(); }

void OutputPublisher::advertise() {
  // Advertise under the lock so that connectCb sees every publisher (stereo_image_proc).
  std::lock_guard<std::mutex> lock(mutex_);
  const ros::SubscriberStatusCallback ros_cb = [this](const ros::SingleSubscriberPublisher&) {
    connectCb();
  };
  const image_transport::SubscriberStatusCallback it_cb =
      [this](const image_transport::SingleSubscriberPublisher&) { connectCb(); };
  pub_disparity_ = nh_.advertise<stereo_msgs::DisparityImage>("disparity", 1, ros_cb, ros_cb);
  pub_points_ = nh_.advertise<sensor_msgs::PointCloud2>("points2", 1, ros_cb, ros_cb);
  pub_stats_ = nh_.advertise<FusionStats>("stats", 10, ros_cb, ros_cb);
  // depth/image_rect + depth/camera_info, as depth_image_proc and image_transport pair them.
  pub_depth_ = it_->advertiseCamera("depth/image_rect", 1, it_cb, it_cb, ros_cb, ros_cb);
  pub_depth_color_ = it_->advertise("depth/image_color", 1, it_cb, it_cb);
  pub_lidar_disparity_ = it_->advertise("lidar_disparity", 1, it_cb, it_cb);
  pub_disparity_image_ = it_->advertise("disparity_image", 1, it_cb, it_cb);
  pub_disparity_color_ = it_->advertise("disparity_image_color", 1, it_cb, it_cb);
  pub_confidence_ = it_->advertise("confidence", 1, it_cb, it_cb);
}

void OutputPublisher::shutdown() {
  diag_timer_.stop();
  std::lock_guard<std::mutex> lock(mutex_);
  shut_down_ = true;
  if (gate_.subscribed()) gate_.unsubscribe();
}

cv::Mat1f outputDepth(const FusionResult& result, const StereoCamera& camera,
                      double max_output_depth) {
  cv::Mat1f depth = result.depth;
  if (depth.empty() && !result.disparity.empty())
    depth = disparityToDepth(result.disparity, camera);
  if (max_output_depth > 0.0) {
    depth = depth.clone();
    depth.setTo(0.f, depth > max_output_depth);
  }
  return depth;
}

void OutputPublisher::connectCb() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (shut_down_) return;
  const uint32_t subscribers =
      pub_disparity_.getNumSubscribers() + pub_points_.getNumSubscribers() +
      pub_stats_.getNumSubscribers() + pub_depth_.getNumSubscribers() +
      pub_depth_color_.getNumSubscribers() + pub_lidar_disparity_.getNumSubscribers() +
      pub_disparity_image_.getNumSubscribers() + pub_disparity_color_.getNumSubscribers() +
      pub_confidence_.getNumSubscribers();
  if (subscribers == 0 && gate_.subscribed()) {
    gate_.unsubscribe();
  } else if (subscribers > 0 && !gate_.subscribed()) {
    gate_.subscribe();
  }
}

void OutputPublisher::setLiveParams(const NodeParams& params) {
  params_.cloud_stride = params.cloud_stride;
  params_.max_output_depth = params.max_output_depth;
  params_.depth_color_max = params.depth_color_max;
}

void OutputPublisher::publish(const InputMatch& match, const StereoCamera& camera,
                              const cv::Mat& left_image, const FusionResult& result,
                              const FusionParams& params, const FrameReport& report) {
  const auto out_start = std::chrono::steady_clock::now();
  const std_msgs::Header& header = match.images.left->header;
  Messages messages;
  makeDisparityMessages(result, camera, params, header, messages);
  makeDepthMessages(result, camera, left_image, match, messages);
  makeLidarMessages(result, camera, header, messages);
  const double total_conversion_ms = report.conversion_ms + msSince(out_start);

  const ros::Time publish_time = ros::Time::now();
  publishMessages(messages);
  ++counters_.processed;
  const double latency_ms =
      latencyMs(publish_time, match.image_stamp, match.images.arrival_ros,
                msSince(match.images.arrival_wall), gate_.clockEpoch() != match.images.clock_epoch);
  if (pub_stats_.getNumSubscribers() > 0) {
    pub_stats_.publish(makeStatsMsg(header, result.stats, report, total_conversion_ms, latency_ms,
                                    (match.sweep_stamp - match.image_stamp).toSec(),
                                    counters_.snapshot()));
  }
  recordFrame(match.image_stamp, result.stats.total_ms + total_conversion_ms, latency_ms);
}

void OutputPublisher::makeDisparityMessages(const FusionResult& result, const StereoCamera& camera,
                                            const FusionParams& params,
                                            const std_msgs::Header& header, Messages& out) const {
  if (pub_disparity_.getNumSubscribers() > 0) {
    out.disparity = conversions::disparityToMsg(result.disparity, header, camera,
                                                params.patchmatch.min_disparity,
                                                params.patchmatch.max_disparity);
  }
  if (pub_disparity_image_.getNumSubscribers() > 0) {
    out.disparity_image = conversions::floatImageToMsg(result.disparity, header);
  }
  if (pub_disparity_color_.getNumSubscribers() > 0) {
    // As depth/image_color, scaled to the frame's disparities (disparityColorScale).
    out.disparity_color = conversions::bgrImageToMsg(
        disparityPicture(result.disparity, params.patchmatch.max_disparity), header);
  }
}

void OutputPublisher::makeDepthMessages(const FusionResult& result, const StereoCamera& camera,
                                        const cv::Mat& left_image, const InputMatch& match,
                                        Messages& out) const {
  const std_msgs::Header& header = match.images.left->header;
  // One depth range for depth/image_rect and points2: the pipeline's (projection max_depth),
  // clipped further by ~max_output_depth.
  const cv::Mat1f depth = outputDepth(result, camera, params_.max_output_depth);
  if (pub_depth_.getNumSubscribers() > 0) {
    out.depth = conversions::depthToMsg(depth, header);
    out.depth_info = boost::make_shared<sensor_msgs::CameraInfo>(*match.images.left_info);
    out.depth_info->header = header;
  }
  if (pub_depth_color_.getNumSubscribers() > 0) {
    // For RViz's Image display: colours with a scale bar in metres (a grey 32FC1 has no legend).
    out.depth_color =
        conversions::bgrImageToMsg(depthPicture(depth, params_.depth_color_max), header);
  }
  if (pub_points_.getNumSubscribers() > 0) {
    out.points =
        conversions::organizedCloudToMsg(depth, left_image, camera, params_.cloud_stride, header);
  }
}

void OutputPublisher::makeLidarMessages(const FusionResult& result, const StereoCamera& camera,
                                        const std_msgs::Header& header, Messages& out) const {
  // Empty for methods without LiDAR: all 0 (= no prior), so the topics always have a message.
  const auto orZeros = [&camera](const cv::Mat1f& image) -> cv::Mat1f {
    if (!image.empty()) return image;
    return cv::Mat1f::zeros(camera.height, camera.width);
  };
  if (pub_lidar_disparity_.getNumSubscribers() > 0) {
    out.prior = conversions::floatImageToMsg(orZeros(result.prior), header);
  }
  if (pub_confidence_.getNumSubscribers() > 0) {
    out.confidence = conversions::floatImageToMsg(orZeros(result.confidence), header);
  }
}

void OutputPublisher::publishMessages(const Messages& m) {
  // Everything as close together as possible.
  if (m.disparity) pub_disparity_.publish(m.disparity);
  if (m.depth) pub_depth_.publish(m.depth, m.depth_info);
  if (m.depth_color) pub_depth_color_.publish(m.depth_color);
  if (m.disparity_image) pub_disparity_image_.publish(m.disparity_image);
  if (m.disparity_color) pub_disparity_color_.publish(m.disparity_color);
  if (m.prior) pub_lidar_disparity_.publish(m.prior);
  if (m.confidence) pub_confidence_.publish(m.confidence);
  if (m.points) pub_points_.publish(m.points);
}

void OutputPublisher::recordFrame(const ros::Time& image_stamp, double total_ms,
                                  double latency_ms) {
  output_frequency_.tick();
  output_stamps_.tick(image_stamp);
  std::lock_guard<std::mutex> lock(mutex_);
  recent_total_ms_.push_back(total_ms);
  recent_latency_ms_.push_back(latency_ms);
  while (recent_total_ms_.size() > kDiagWindow) recent_total_ms_.pop_front();
  while (recent_latency_ms_.size() > kDiagWindow) recent_latency_ms_.pop_front();
}

void OutputPublisher::diagnoseOutput(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  if (!gate_.subscribed()) {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "idle: no subscriber on any output");
    return;
  }
  // FrequencyStatus measures its window in ROS time: start it again when time restarted (a loop).
  const uint32_t epoch = gate_.clockEpoch();
  if (epoch != diag_clock_epoch_) {
    diag_clock_epoch_ = epoch;
    output_frequency_.clear();
  }
  output_frequency_.run(stat);
  diagnostic_updater::DiagnosticStatusWrapper stamps;
  output_stamps_.run(stamps);
  stat.mergeSummary(stamps.level, stamps.message);
  for (const auto& kv : stamps.values) stat.add(kv.key, kv.value);
}

void OutputPublisher::setSearchEffort(bool reduced, const std::string& text) {
  std::lock_guard<std::mutex> lock(mutex_);
  effort_reduced_ = reduced;
  effort_text_ = text;
}

void OutputPublisher::diagnoseProcessing(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  double mean_ms = 0, max_ms = 0, mean_latency = 0;
  std::size_t n = 0;
  const CounterSnapshot c = counters_.snapshot();
  uint32_t new_problems = 0;
  bool reduced = false;
  std::string effort;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    reduced = effort_reduced_;
    effort = effort_text_;
    n = recent_total_ms_.size();
    if (n > 0) {
      mean_ms = std::accumulate(recent_total_ms_.begin(), recent_total_ms_.end(), 0.0) / n;
      max_ms = *std::max_element(recent_total_ms_.begin(), recent_total_ms_.end());
      mean_latency = std::accumulate(recent_latency_ms_.begin(), recent_latency_ms_.end(), 0.0) / n;
    }
    new_problems = c.problems() - diag_last_problems_;
    diag_last_problems_ = c.problems();
  }
  if (new_problems != 0) {
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                  "%u input sets skipped or dropped since the last report (see the counters)",
                  new_problems);
  } else if (reduced) {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                 "search reduced to keep the input's rate (keep_rate): " + effort);
  } else {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "ok");
  }
  stat.add("search effort", effort);
  stat.add("processing time mean [ms]", mean_ms);
  stat.add("processing time max [ms]", max_ms);
  stat.add("latency mean [ms]", mean_latency);
  stat.add("frames averaged", n);
  stat.add("processed frames", c.processed);
  stat.add("dropped frames", c.dropped);
  stat.add("unmatched frames", c.unmatched);
  stat.add("tf failures", c.tf_failures);
  stat.add("ego-motion failures", c.motion_failures);
  stat.add("invalid inputs", c.invalid);
  stat.add("out of order", c.out_of_order);
  stat.add("processing errors", c.errors);
  stat.add("rate limited (max_rate)", c.rate_limited);
}

}  // namespace lidar_stereo_fusion
