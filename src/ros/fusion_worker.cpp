#include "lidar_stereo_fusion/ros/fusion_worker.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <numeric>
#include <sstream>
#include <utility>

#include <tf2_eigen/tf2_eigen.h>
#include <boost/bind/bind.hpp>
#include <boost/make_shared.hpp>

#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/ros/conversions.h"
#include "lidar_stereo_fusion/ros/ros_params.h"
#include "lidar_stereo_fusion/ros/stats_publisher.h"

namespace lidar_stereo_fusion {

namespace {

constexpr double kThrottlePeriod = 5.0;  ///< [s] per topic and problem
constexpr std::size_t kDiagWindow = 30;  ///< frames averaged in the processing diagnostics
constexpr std::size_t kMaxLogKeys = 64;  ///< (topic, kind) pairs remembered by the throttle

const char* const kLeftImage = "left/image_rect_color";
const char* const kLeftInfo = "left/camera_info";
const char* const kRightImage = "right/image_rect_color";
const char* const kRightInfo = "right/camera_info";
const char* const kCloud = "velodyne_points";

std::string stampText(const ros::Time& t) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(6) << t.toSec();
  return s.str();
}

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

/// Reads `name` and keeps the current value (with an error naming the parameter) when `ok` fails.
template <class T, class Check>
void readChecked(const ros::NodeHandle& pnh, const std::string& name, T& value, Check ok,
                 const char* requirement) {
  if (!pnh.hasParam(name)) return;
  T candidate = value;
  if (!pnh.getParam(name, candidate)) {
    ROS_ERROR_STREAM("parameter " << pnh.resolveName(name) << " has the wrong type; keeping "
                                  << value);
    return;
  }
  if (!ok(candidate)) {
    ROS_ERROR_STREAM("parameter " << pnh.resolveName(name) << " = " << candidate << " is invalid ("
                                  << requirement << "); keeping " << value);
    return;
  }
  value = candidate;
}

}  // namespace

NodeParams NodeParams::read(const ros::NodeHandle& pnh) {
  NodeParams p;
  const auto any = [](auto) { return true; };
  const auto positive = [](auto v) { return v > 0; };
  const auto non_negative = [](auto v) { return v >= 0; };
  readChecked(pnh, "approximate_sync", p.approximate_sync, any, "");
  readChecked(pnh, "queue_size", p.queue_size, positive, "must be > 0");
  readChecked(pnh, "max_time_offset", p.max_time_offset, non_negative, "must be >= 0 [s]");
  readChecked(pnh, "max_sweep_wait", p.max_sweep_wait, non_negative, "must be >= 0 [s]");
  readChecked(pnh, "sweep_buffer_size", p.sweep_buffer_size, positive, "must be > 0");
  readChecked(pnh, "tf_timeout", p.tf_timeout, non_negative, "must be >= 0 [s]");
  readChecked(pnh, "num_rings", p.num_rings, positive, "must be > 0");
  readChecked(pnh, "cloud_stride", p.cloud_stride, positive, "must be > 0");
  readChecked(pnh, "max_output_depth", p.max_output_depth, non_negative, "must be >= 0 [m]");
  readChecked(pnh, "max_rate", p.max_rate, non_negative, "must be >= 0 [Hz] (0 = no limit)");
  readChecked(
      pnh, "worker_nice", p.worker_nice, [](int v) { return v >= 0 && v <= 19; },
      "must be in [0, 19]");
  readChecked(pnh, "diagnostics/min_rate", p.diag_min_rate, non_negative, "must be >= 0 [Hz]");
  readChecked(pnh, "diagnostics/max_rate", p.diag_max_rate, positive, "must be > 0 [Hz]");
  readChecked(pnh, "diagnostics/max_latency", p.diag_max_latency, positive, "must be > 0 [s]");
  return p;
}

// -------------------------------------------------------------------------------------------------
// Setup
// -------------------------------------------------------------------------------------------------
FusionWorker::FusionWorker(const ros::NodeHandle& nh, const ros::NodeHandle& pnh,
                           const std::string& name)
    : nh_(nh),
      pnh_(pnh),
      name_(name),
      node_params_(NodeParams::read(pnh)),
      tf_listener_(tf_buffer_),
      updater_(nh, pnh, name),
      output_frequency_(diagnostic_updater::FrequencyStatusParam(
          &node_params_.diag_min_rate, &node_params_.diag_max_rate, 0.1, 10)),
      output_stamps_(
          diagnostic_updater::TimeStampStatusParam(-1.0, node_params_.diag_max_latency)) {
  // Core parameters: the defaults of the structs, overridden by what is on the parameter server.
  std::vector<std::string> errors;
  FusionParams params = ros_params::readParams(pnh_, FusionParams(), &errors);
  for (const auto& e : errors) ROS_ERROR_STREAM("[" << name_ << "] " << e);
  try {
    params.validate();
  } catch (const std::exception& e) {
    ROS_ERROR_STREAM("[" << name_ << "] parameters rejected (" << e.what()
                         << "); using the defaults of FusionParams");
    params = FusionParams();
  }
  params_ = params;
  ros_params::writeParams(pnh_, params_);

  Matcher::Params mp;
  mp.max_time_offset = node_params_.max_time_offset;
  mp.max_wait = node_params_.max_sweep_wait;
  mp.sweep_buffer_size = static_cast<std::size_t>(node_params_.sweep_buffer_size);
  matcher_.setParams(mp);

  // Synchroniser of the image set (connected once; the filters are (un)subscribed lazily).
  it_ = std::make_shared<image_transport::ImageTransport>(nh_);
  if (node_params_.approximate_sync) {
    approx_sync_ =
        std::make_shared<ApproxSync>(ApproxPolicy(node_params_.queue_size), sub_left_image_,
                                     sub_left_info_, sub_right_image_, sub_right_info_);
    approx_sync_->setReset(true);  // clears its queues when simulated time jumps back
    approx_sync_->registerCallback(boost::bind(&FusionWorker::imageCb, this,
                                               boost::placeholders::_1, boost::placeholders::_2,
                                               boost::placeholders::_3, boost::placeholders::_4));
  } else {
    exact_sync_ = std::make_shared<ExactSync>(ExactPolicy(node_params_.queue_size), sub_left_image_,
                                              sub_left_info_, sub_right_image_, sub_right_info_);
    exact_sync_->setReset(true);
    exact_sync_->registerCallback(boost::bind(&FusionWorker::imageCb, this, boost::placeholders::_1,
                                              boost::placeholders::_2, boost::placeholders::_3,
                                              boost::placeholders::_4));
    exact_sync_->registerDropCallback(
        boost::bind(&FusionWorker::syncDropCb, this, boost::placeholders::_1,
                    boost::placeholders::_2, boost::placeholders::_3, boost::placeholders::_4));
  }

  // Live parameters: start from the values just read, then follow dynamic_reconfigure.
  reconfigure_server_ =
      std::make_unique<dynamic_reconfigure::Server<FusionConfig>>(reconfigure_mutex_, pnh_);
  reconfigure_server_->updateConfig(ros_params::toConfig(params_));
  reconfigure_server_->setCallback(boost::bind(&FusionWorker::reconfigureCb, this,
                                               boost::placeholders::_1, boost::placeholders::_2));

  // Diagnostics.
  updater_.setHardwareID("none");
  updater_.add("output", this, &FusionWorker::diagnoseOutput);
  updater_.add("processing", this, &FusionWorker::diagnoseProcessing);
  diag_timer_ =
      nh_.createTimer(ros::Duration(0.5), [this](const ros::TimerEvent&) { updater_.update(); });

  worker_ = std::thread(&FusionWorker::workerLoop, this);
  advertise();  // last: connect callbacks may subscribe right away

  ROS_INFO_STREAM("[" << name_ << "] method " << methodName(params_.method) << ", "
                      << (node_params_.approximate_sync ? "approximate" : "exact")
                      << " image sync, sweeps matched within " << node_params_.max_time_offset
                      << " s; waiting for subscribers on the outputs");
}

FusionWorker::~FusionWorker() {
  {
    std::lock_guard<std::mutex> lock(connect_mutex_);
    if (subscribed_) unsubscribe();
  }
  diag_timer_.stop();
  {
    std::lock_guard<std::mutex> lock(data_mutex_);
    stop_ = true;
  }
  job_cv_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void FusionWorker::advertise() {
  // Advertise under the connect mutex so that connectCb sees every publisher (stereo_image_proc).
  std::lock_guard<std::mutex> lock(connect_mutex_);
  const ros::SubscriberStatusCallback ros_cb = [this](const ros::SingleSubscriberPublisher&) {
    connectCb();
  };
  const image_transport::SubscriberStatusCallback it_cb =
      [this](const image_transport::SingleSubscriberPublisher&) { connectCb(); };
  pub_disparity_ = nh_.advertise<stereo_msgs::DisparityImage>("disparity", 1, ros_cb, ros_cb);
  pub_points_ = nh_.advertise<sensor_msgs::PointCloud2>("points2", 1, ros_cb, ros_cb);
  pub_stats_ = advertiseStats(nh_, "stats", 10, ros_cb);
  pub_depth_ = it_->advertise("depth", 1, it_cb, it_cb);
  pub_depth_info_ = nh_.advertise<sensor_msgs::CameraInfo>("depth/camera_info", 1, ros_cb, ros_cb);
  pub_lidar_disparity_ = it_->advertise("lidar_disparity", 1, it_cb, it_cb);
  pub_disparity_image_ = it_->advertise("disparity_image", 1, it_cb, it_cb);
  pub_confidence_ = it_->advertise("confidence", 1, it_cb, it_cb);
}

void FusionWorker::connectCb() {
  std::lock_guard<std::mutex> lock(connect_mutex_);
  const uint32_t subscribers =
      pub_disparity_.getNumSubscribers() + pub_points_.getNumSubscribers() +
      pub_stats_.getNumSubscribers() + pub_depth_.getNumSubscribers() +
      pub_depth_info_.getNumSubscribers() + pub_lidar_disparity_.getNumSubscribers() +
      pub_disparity_image_.getNumSubscribers() + pub_confidence_.getNumSubscribers();
  if (subscribers == 0 && subscribed_) {
    unsubscribe();
  } else if (subscribers > 0 && !subscribed_) {
    subscribe();
  }
}

void FusionWorker::subscribe() {
  const image_transport::TransportHints hints("raw", ros::TransportHints(), pnh_);
  const uint32_t q = static_cast<uint32_t>(node_params_.queue_size);
  sub_left_image_.subscribe(*it_, kLeftImage, q, hints);
  sub_left_info_.subscribe(nh_, kLeftInfo, q);
  sub_right_image_.subscribe(*it_, kRightImage, q, hints);
  sub_right_info_.subscribe(nh_, kRightInfo, q);
  sub_cloud_ = nh_.subscribe(kCloud, 2, &FusionWorker::cloudCb, this);
  subscribed_ = true;
  ROS_DEBUG_STREAM("[" << name_ << "] subscribed to the inputs");
}

void FusionWorker::unsubscribe() {
  sub_left_image_.unsubscribe();
  sub_left_info_.unsubscribe();
  sub_right_image_.unsubscribe();
  sub_right_info_.unsubscribe();
  sub_cloud_.shutdown();
  subscribed_ = false;
  std::lock_guard<std::mutex> lock(data_mutex_);
  // Sets in flight when the last subscriber leaves are dropped, and counted.
  const std::size_t pending = matcher_.clear() + (next_job_ ? 1 : 0);
  next_job_.reset();
  counters_.dropped += static_cast<uint32_t>(pending);
  ROS_DEBUG_STREAM("[" << name_ << "] no subscribers left: unsubscribed from the inputs");
}

std::string FusionWorker::topicName(const std::string& relative) const {
  return nh_.resolveName(relative);
}

void FusionWorker::logThrottled(Level level, const std::string& topic, const std::string& kind,
                                const std::string& text) {
  const ros::WallTime now = ros::WallTime::now();
  const std::string key = topic + '|' + kind;
  {
    std::lock_guard<std::mutex> lock(log_mutex_);
    auto it = last_log_.find(key);
    if (it != last_log_.end() && (now - it->second).toSec() < kThrottlePeriod) return;
    // Topics and kinds are fixed words, so this never triggers in practice; it bounds the map
    // whatever a caller passes.
    if (it == last_log_.end() && last_log_.size() >= kMaxLogKeys) last_log_.clear();
    last_log_[key] = now;
  }
  switch (level) {
    case Level::kInfo:
      ROS_INFO_STREAM("[" << name_ << "] " << text);
      break;
    case Level::kWarn:
      ROS_WARN_STREAM("[" << name_ << "] " << text);
      break;
    default:
      ROS_ERROR_STREAM("[" << name_ << "] " << text);
  }
}

// -------------------------------------------------------------------------------------------------
// Callbacks
// -------------------------------------------------------------------------------------------------
void FusionWorker::detectClockJump() {
  // Called with data_mutex_ held. A bag played with --loop sends the clock back: forget the
  // buffered stamps, or every later message would count as out of order.
  const ros::Time now = ros::Time::now();
  if (!last_clock_.isZero() && now + ros::Duration(0.5) < last_clock_) {
    const std::size_t dropped = matcher_.clear();
    counters_.dropped += static_cast<uint32_t>(dropped);
    logThrottled(Level::kInfo, "clock", "jump",
                 "ROS time jumped back from " + stampText(last_clock_) + " to " + stampText(now) +
                     ": sweep and image buffers cleared (bag loop?)");
  }
  last_clock_ = now;
}

bool FusionWorker::checkImageSet(const ImageSet& set) {
  // `kind`: a fixed word per kind of problem, the throttle key with the topic.
  const auto reject = [this](const std::string& topic, const char* kind, const std::string& problem,
                             const ros::Time& stamp) {
    ++counters_.invalid;
    warnThrottled(
        topic, kind,
        topicName(topic) + ": " + problem + " (stamp " + stampText(stamp) + "); image set skipped");
    return false;
  };
  const ros::Time stamp = set.left->header.stamp;
  std::string problem = conversions::checkImage(*set.left);
  if (!problem.empty()) return reject(kLeftImage, "image", problem, stamp);
  problem = conversions::checkImage(*set.right);
  if (!problem.empty()) return reject(kRightImage, "image", problem, stamp);
  if (set.left->width != set.right->width || set.left->height != set.right->height) {
    return reject(kRightImage, "size",
                  "size " + std::to_string(set.right->width) + "x" +
                      std::to_string(set.right->height) + " differs from the left image's " +
                      std::to_string(set.left->width) + "x" + std::to_string(set.left->height),
                  stamp);
  }
  if (set.left_info->width != set.left->width || set.left_info->height != set.left->height) {
    return reject(kLeftInfo, "size",
                  "camera_info is " + std::to_string(set.left_info->width) + "x" +
                      std::to_string(set.left_info->height) + " but the image is " +
                      std::to_string(set.left->width) + "x" + std::to_string(set.left->height),
                  stamp);
  }
  if (set.right_info->width != set.right->width || set.right_info->height != set.right->height) {
    return reject(kRightInfo, "size",
                  "camera_info is " + std::to_string(set.right_info->width) + "x" +
                      std::to_string(set.right_info->height) + " but the image is " +
                      std::to_string(set.right->width) + "x" + std::to_string(set.right->height),
                  stamp);
  }
  try {
    conversions::stereoCameraFromInfo(*set.left_info, *set.right_info);
  } catch (const conversions::ConversionError& e) {
    return reject(kRightInfo, "calibration", e.what(), stamp);
  }
  if (set.left->header.frame_id.empty()) {
    return reject(kLeftImage, "frame_id",
                  "empty frame_id (the left optical frame is needed for TF)", stamp);
  }
  return true;
}

void FusionWorker::imageCb(const ImageConstPtr& left, const InfoConstPtr& left_info,
                           const ImageConstPtr& right, const InfoConstPtr& right_info) {
  ROS_DEBUG_STREAM("[" << name_ << "] image set " << stampText(left->header.stamp));
  const ros::Time stamp = left->header.stamp;
  if (node_params_.max_rate > 0.0) {
    // ~max_rate: sets closer than the period (less 10 % for stamp jitter) to the last accepted one
    // are dropped here, before any work; counted, never warned about (the user asked for it).
    std::lock_guard<std::mutex> lock(data_mutex_);
    const double min_step = 0.9 / node_params_.max_rate;
    if (!last_accepted_stamp_.isZero() && stamp >= last_accepted_stamp_ &&
        (stamp - last_accepted_stamp_).toSec() < min_step) {
      ++counters_.rate_limited;
      return;
    }
    last_accepted_stamp_ = stamp;
  }
  ImageSet set{left, right, left_info, right_info, ros::Time::now(), Clock::now()};
  if (!checkImageSet(set)) return;
  std::lock_guard<std::mutex> lock(data_mutex_);
  detectClockJump();
  Matcher::Events events = matcher_.addImages(stamp, std::move(set), ros::Time::now());
  handleEvents(events, kLeftImage, stamp);
}

void FusionWorker::syncDropCb(const ImageConstPtr& left, const InfoConstPtr& left_info,
                              const ImageConstPtr& right, const InfoConstPtr& right_info) {
  // ExactTime gave up on an incomplete set (a partner message never came with the same stamp).
  ++counters_.unmatched;
  std::string missing;
  if (!left) missing += std::string(" ") + topicName(kLeftImage);
  if (!left_info) missing += std::string(" ") + topicName(kLeftInfo);
  if (!right) missing += std::string(" ") + topicName(kRightImage);
  if (!right_info) missing += std::string(" ") + topicName(kRightInfo);
  ros::Time stamp;
  if (left)
    stamp = left->header.stamp;
  else if (right)
    stamp = right->header.stamp;
  else if (left_info)
    stamp = left_info->header.stamp;
  else if (right_info)
    stamp = right_info->header.stamp;
  warnThrottled("image set", "incomplete",
                "incomplete image set at stamp " + stampText(stamp) +
                    " dropped by the exact-time synchroniser; missing:" + missing +
                    " (different stamps? then set ~approximate_sync true)");
}

void FusionWorker::cloudCb(const CloudConstPtr& cloud) {
  const ros::Time stamp = cloud->header.stamp;
  ROS_DEBUG_STREAM("[" << name_ << "] sweep " << stampText(stamp) << " ("
                       << static_cast<uint64_t>(cloud->width) * cloud->height << " points)");
  std::string problem = conversions::checkCloudLayout(*cloud);
  const char* kind = "layout";  // the throttle key with the topic
  if (problem.empty() && (cloud->width == 0 || cloud->height == 0)) {
    problem = "empty cloud (0 points)";
    kind = "empty";
  }
  if (problem.empty() && cloud->header.frame_id.empty()) {
    problem = "empty frame_id";
    kind = "frame_id";
  }
  if (!problem.empty()) {
    ++counters_.invalid;
    warnThrottled(
        kCloud, kind,
        topicName(kCloud) + ": " + problem + " (stamp " + stampText(stamp) + "); sweep skipped");
    return;
  }
  std::lock_guard<std::mutex> lock(data_mutex_);
  detectClockJump();
  Matcher::Events events = matcher_.addSweep(stamp, cloud, ros::Time::now());
  handleEvents(events, kCloud, stamp);
}

void FusionWorker::handleEvents(Matcher::Events& events, const std::string& topic,
                                const ros::Time& stamp) {
  // Called with data_mutex_ held.
  if (events.restarted) {
    counters_.dropped += static_cast<uint32_t>(events.discarded);
    std::ostringstream text;
    text << topicName(topic) << ": stamp " << stampText(stamp) << " is more than "
         << matcher_.params().restart_step
         << " s older than the last one: time restarted (bag loop?), buffers cleared";
    logThrottled(Level::kInfo, topic, "restart", text.str());
  }
  if (events.out_of_order) {
    ++counters_.out_of_order;
    warnThrottled(topic, "order",
                  topicName(topic) + ": stamp " + stampText(stamp) +
                      " is not newer than one already received (out of order or "
                      "duplicate); message dropped");
  }
  for (std::size_t i = 0; i < events.unmatched.size(); ++i) {
    ++counters_.unmatched;
    const std::string at = " of the image set at " + stampText(events.unmatched[i]);
    if (events.unmatched_waited[i]) {  // no sweep at or after the set came in time
      warnThrottled(kCloud, "late",
                    "no sweep on " + topicName(kCloud) + " stamped at or after the image set at " +
                        stampText(events.unmatched[i]) + " arrived within ~max_sweep_wait = " +
                        std::to_string(node_params_.max_sweep_wait) +
                        " s (ROS time), and none before it within ~max_time_offset = " +
                        std::to_string(node_params_.max_time_offset) +
                        " s; image set skipped (is the LiDAR publishing? raise ~max_sweep_wait "
                        "if its sweeps arrive late)");
    } else {
      warnThrottled(kCloud, "unmatched",
                    "no sweep on " + topicName(kCloud) + " within ~max_time_offset = " +
                        std::to_string(node_params_.max_time_offset) + " s" + at +
                        "; image set skipped (raise ~max_time_offset if the clocks differ)");
    }
  }
  if (events.ready.empty()) return;
  ROS_DEBUG_STREAM("[" << name_ << "] matched image set "
                       << stampText(events.ready.back().image_stamp) << " with sweep "
                       << stampText(events.ready.back().sweep_stamp));
  // Only the newest set is worth processing: older ones (and a set still waiting for the worker)
  // are dropped and counted, so a slow pipeline never builds a backlog.
  const std::size_t superseded = events.ready.size() - 1 + (next_job_ ? 1 : 0);
  counters_.dropped += static_cast<uint32_t>(superseded);
  next_job_ = std::move(events.ready.back());
  job_cv_.notify_one();
}

void FusionWorker::reconfigureCb(FusionConfig& config, uint32_t /*level*/) {
  FusionParams current;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    current = params_;
  }
  FusionParams candidate;
  try {
    candidate = ros_params::fromConfig(config);
    candidate.validate();
  } catch (const std::exception& e) {
    std::string changes = ros_params::describeChanges(current, candidate);
    ROS_ERROR_STREAM("[" << name_ << "] rejected parameter change (" << changes << "): " << e.what()
                         << "; keeping the previous parameters");
    config = ros_params::toConfig(current);  // the server publishes the values in use
    return;
  }
  const std::string changes = ros_params::describeChanges(current, candidate);
  if (changes.empty()) return;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    params_ = candidate;
    params_changed_ = true;
  }
  ros_params::writeParams(pnh_, candidate);
  ROS_INFO_STREAM("[" << name_ << "] parameters changed: " << changes);
}

// -------------------------------------------------------------------------------------------------
// Worker thread
// -------------------------------------------------------------------------------------------------
void FusionWorker::workerLoop() {
  if (node_params_.worker_nice > 0) {
    // Linux: the nice value is per thread and inherited by the threads this one creates (OpenMP).
    const auto tid = static_cast<id_t>(syscall(SYS_gettid));
    errno = 0;
    const int current = getpriority(PRIO_PROCESS, tid);
    if (errno != 0 || setpriority(PRIO_PROCESS, tid, current + node_params_.worker_nice) != 0) {
      ROS_WARN_STREAM("[" << name_ << "] could not lower the priority of the worker thread: "
                          << std::strerror(errno));
    }
  }
  FusionParams params;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    params = params_;
    params_changed_ = false;
  }
  FusionPipeline pipeline(params);
  while (true) {
    boost::optional<Match> job;
    {
      std::unique_lock<std::mutex> lock(data_mutex_);
      job_cv_.wait_for(lock, std::chrono::milliseconds(20),
                       [this] { return stop_ || static_cast<bool>(next_job_); });
      if (stop_) return;
      // Image sets that waited max_sweep_wait (ROS time) for a later sweep are decided here.
      Matcher::Events events = matcher_.poll(ros::Time::now());
      handleEvents(events, kLeftImage, ros::Time());
      if (!next_job_) continue;
      job = std::move(next_job_);
      next_job_.reset();
    }
    {
      std::lock_guard<std::mutex> lock(params_mutex_);
      if (params_changed_) {
        pipeline.setParams(params_);  // validated in reconfigureCb
        params_changed_ = false;
      }
    }
    try {
      processMatch(*job, pipeline);
    } catch (const std::exception& e) {  // last line of defence: the worker thread must not die
      ++counters_.errors;
      logThrottled(Level::kError, "pipeline", "error",
                   std::string("frame at ") + stampText(job->image_stamp) + " failed: " + e.what() +
                       "; frame skipped");
    }
  }
}

void FusionWorker::processMatch(const Match& match, FusionPipeline& pipeline) {
  const ImageSet& set = match.images;
  const sensor_msgs::PointCloud2& cloud_msg = *match.sweep;
  const std::string& camera_frame = set.left->header.frame_id;
  const std::string& lidar_frame = cloud_msg.header.frame_id;

  // Extrinsics at the sweep stamp; a short timeout bounds the wait (worker thread only).
  FusionInput input;
  try {
    const geometry_msgs::TransformStamped tf = tf_buffer_.lookupTransform(
        camera_frame, lidar_frame, match.sweep_stamp, ros::Duration(node_params_.tf_timeout));
    input.T_cam_lidar = tf2::transformToEigen(tf);
  } catch (const tf2::TransformException& e) {
    ++counters_.tf_failures;
    warnThrottled(kCloud, "tf",
                  "no transform from '" + lidar_frame + "' (" + topicName(kCloud) + ") to '" +
                      camera_frame + "' (" + topicName(kLeftImage) + ") at sweep stamp " +
                      stampText(match.sweep_stamp) + " within " +
                      std::to_string(node_params_.tf_timeout) + " s: " + e.what() +
                      "; frame skipped");
    return;
  }

  const auto conversion_start = Clock::now();
  conversions::CloudConversion cloud;
  try {
    conversions::stereoPairToCore(set.left, set.right, input.left, input.right);
    input.camera = conversions::stereoCameraFromInfo(*set.left_info, *set.right_info);
    cloud = conversions::cloudFromMsg(cloud_msg);
  } catch (const std::exception& e) {  // ConversionError, and anything OpenCV lets through
    ++counters_.invalid;
    warnThrottled("input set", "convert",
                  std::string("cannot convert the input set at ") + stampText(match.image_stamp) +
                      ": " + e.what() + "; frame skipped");
    return;
  }
  if (cloud.cloud.empty()) {
    ++counters_.invalid;
    warnThrottled(kCloud, "nan",
                  topicName(kCloud) + ": none of the " + std::to_string(cloud.total_points) +
                      " points of the sweep at " + stampText(match.sweep_stamp) +
                      " is finite (all NaN / inf); frame skipped");
    return;
  }
  // The ring field if plausible, else the offline sweep-order rule, else elevation; each checked.
  const RingRecovery rings = ensureRings(cloud.cloud, cloud.has_ring, node_params_.num_rings);
  if (!rings.plausible) {
    warnThrottled(kCloud, "rings",
                  topicName(kCloud) + ": no plausible scan lines in the sweep at " +
                      stampText(match.sweep_stamp) + " (" + rings.fallbacks + "); using " +
                      std::to_string(rings.rings) + " rings by " + ringSourceName(rings.source) +
                      ", the prior will be coarse (publish the driver's ring field, or set "
                      "~num_rings to the sensor's beam count)");
  }
  input.cloud = std::move(cloud.cloud);
  const double conversion_ms = msSince(conversion_start);

  FusionResult result;
  try {
    result = pipeline.process(input);
  } catch (const std::exception& e) {
    ++counters_.errors;
    logThrottled(Level::kError, "pipeline", "error",
                 "fusion failed on the frame at " + stampText(match.image_stamp) + ": " + e.what() +
                     "; frame skipped");
    return;
  }
  ROS_DEBUG_STREAM("[" << name_ << "] processed " << stampText(match.image_stamp) << " in "
                       << result.stats.total_ms << " ms");
  publishOutputs(match, input.camera, input.left, result, pipeline.params(),
                 static_cast<int>(input.cloud.size()), rings, conversion_ms);
}

void FusionWorker::publishOutputs(const Match& match, const StereoCamera& camera,
                                  const cv::Mat& left_image, const FusionResult& result,
                                  const FusionParams& params, int cloud_points,
                                  const RingRecovery& rings, double conversion_ms) {
  const auto out_start = Clock::now();
  const std_msgs::Header& header = match.images.left->header;
  cv::Mat1f depth = result.depth;
  if (depth.empty() && !result.disparity.empty())
    depth = disparityToDepth(result.disparity, camera);

  stereo_msgs::DisparityImagePtr disparity_msg;
  sensor_msgs::ImagePtr depth_msg, prior_msg, disparity_image_msg, confidence_msg;
  sensor_msgs::CameraInfoPtr depth_info;
  sensor_msgs::PointCloud2Ptr points_msg;
  if (pub_disparity_.getNumSubscribers() > 0) {
    disparity_msg = conversions::disparityToMsg(result.disparity, header, camera,
                                                params.patchmatch.min_disparity,
                                                params.patchmatch.max_disparity);
  }
  if (pub_disparity_image_.getNumSubscribers() > 0) {
    disparity_image_msg = conversions::floatImageToMsg(result.disparity, header);
  }
  if (pub_depth_.getNumSubscribers() > 0) {
    depth_msg = conversions::depthToMsg(depth, header, node_params_.max_output_depth);
  }
  if (pub_depth_info_.getNumSubscribers() > 0) {
    depth_info = boost::make_shared<sensor_msgs::CameraInfo>(*match.images.left_info);
    depth_info->header = header;
  }
  if (pub_lidar_disparity_.getNumSubscribers() > 0) {
    const cv::Mat1f prior =
        result.prior.empty() ? cv::Mat1f::zeros(camera.height, camera.width) : result.prior;
    prior_msg = conversions::floatImageToMsg(prior, header);
  }
  if (pub_confidence_.getNumSubscribers() > 0) {
    // Empty for methods without LiDAR: all 0 (= no prior), so the topic always has a message.
    const cv::Mat1f confidence = result.confidence.empty()
                                     ? cv::Mat1f::zeros(camera.height, camera.width)
                                     : result.confidence;
    confidence_msg = conversions::floatImageToMsg(confidence, header);
  }
  if (pub_points_.getNumSubscribers() > 0) {
    cv::Mat1f clipped = depth;
    if (node_params_.max_output_depth > 0.0) {
      clipped = depth.clone();
      clipped.setTo(0.f, depth > node_params_.max_output_depth);
    }
    points_msg = conversions::coloredCloudToMsg(
        makeColoredCloud(clipped, left_image, camera, node_params_.cloud_stride), header);
  }
  const double total_conversion_ms = conversion_ms + msSince(out_start);

  // Publish everything as close together as possible; latency = now - image stamp.
  const ros::Time publish_time = ros::Time::now();
  if (disparity_msg) pub_disparity_.publish(disparity_msg);
  if (depth_msg) pub_depth_.publish(depth_msg);
  if (depth_info) pub_depth_info_.publish(depth_info);
  if (disparity_image_msg) pub_disparity_image_.publish(disparity_image_msg);
  if (prior_msg) pub_lidar_disparity_.publish(prior_msg);
  if (confidence_msg) pub_confidence_.publish(confidence_msg);
  if (points_msg) pub_points_.publish(points_msg);
  const uint32_t processed = ++counters_.processed;
  // Latency = publish time - image stamp in ROS time; when ROS time went back since the set
  // arrived (a bag loop), the arrival's latency plus the wall time since then.
  const double latency_ms = publish_time >= match.images.arrival_ros
                                ? (publish_time - match.image_stamp).toSec() * 1e3
                                : (match.images.arrival_ros - match.image_stamp).toSec() * 1e3 +
                                      msSince(match.images.arrival_wall);

  if (pub_stats_.getNumSubscribers() > 0) {
    StatsReport r;
    r.method = methodName(params.method);
    const FrameStats& s = result.stats;
    r.projection_ms = static_cast<float>(s.projection_ms);
    r.upsampling_ms = static_cast<float>(s.upsampling_ms);
    r.patchmatch_ms = static_cast<float>(s.patchmatch_ms);
    r.depth_ms = static_cast<float>(s.depth_ms);
    r.total_ms = static_cast<float>(s.total_ms);
    r.conversion_ms = static_cast<float>(total_conversion_ms);
    r.latency_ms = static_cast<float>(latency_ms);
    r.sweep_time_offset = static_cast<float>((match.sweep_stamp - match.image_stamp).toSec());
    r.points_in_cloud = cloud_points;
    r.points_in_front = s.points_in_front;
    r.points_projected = s.points_projected;
    r.points_removed = s.points_removed;
    r.rings = rings.rings;
    r.rings_recovered = rings.source != RingSource::kField;
    r.ring_method = ringSourceName(rings.source);
    r.rings_plausible = rings.plausible;
    r.prior_coverage = static_cast<float>(s.prior_coverage);
    r.output_coverage = static_cast<float>(s.output_coverage);
    r.processed_frames = processed;
    r.dropped_frames = counters_.dropped;
    r.unmatched_frames = counters_.unmatched;
    r.tf_failures = counters_.tf_failures;
    r.invalid_inputs = counters_.invalid;
    r.out_of_order = counters_.out_of_order;
    r.processing_errors = counters_.errors;
    r.rate_limited = counters_.rate_limited;
    publishStats(pub_stats_, header, r);
  }

  output_frequency_.tick();
  output_stamps_.tick(match.image_stamp);
  std::lock_guard<std::mutex> lock(diag_mutex_);
  recent_total_ms_.push_back(result.stats.total_ms + total_conversion_ms);
  recent_latency_ms_.push_back(latency_ms);
  while (recent_total_ms_.size() > kDiagWindow) recent_total_ms_.pop_front();
  while (recent_latency_ms_.size() > kDiagWindow) recent_latency_ms_.pop_front();
}

// -------------------------------------------------------------------------------------------------
// Diagnostics
// -------------------------------------------------------------------------------------------------
void FusionWorker::diagnoseOutput(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  bool subscribed;
  {
    std::lock_guard<std::mutex> lock(connect_mutex_);
    subscribed = subscribed_;
  }
  if (!subscribed) {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "idle: no subscriber on any output");
    return;
  }
  output_frequency_.run(stat);
  diagnostic_updater::DiagnosticStatusWrapper stamps;
  output_stamps_.run(stamps);
  stat.mergeSummary(stamps.level, stamps.message);
  for (const auto& kv : stamps.values) stat.add(kv.key, kv.value);
}

void FusionWorker::diagnoseProcessing(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  double mean_ms = 0, max_ms = 0, mean_latency = 0;
  std::size_t n = 0;
  {
    std::lock_guard<std::mutex> lock(diag_mutex_);
    n = recent_total_ms_.size();
    if (n > 0) {
      mean_ms = std::accumulate(recent_total_ms_.begin(), recent_total_ms_.end(), 0.0) / n;
      max_ms = *std::max_element(recent_total_ms_.begin(), recent_total_ms_.end());
      mean_latency = std::accumulate(recent_latency_ms_.begin(), recent_latency_ms_.end(), 0.0) / n;
    }
  }
  const uint32_t problems = counters_.dropped + counters_.unmatched + counters_.tf_failures +
                            counters_.invalid + counters_.out_of_order + counters_.errors;
  if (problems != diag_last_problems_) {
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                  "%u input sets skipped or dropped since the last report (see the counters)",
                  problems - diag_last_problems_);
  } else {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "ok");
  }
  diag_last_problems_ = problems;
  stat.add("processing time mean [ms]", mean_ms);
  stat.add("processing time max [ms]", max_ms);
  stat.add("latency mean [ms]", mean_latency);
  stat.add("frames averaged", n);
  stat.add("processed frames", counters_.processed.load());
  stat.add("dropped frames", counters_.dropped.load());
  stat.add("unmatched frames", counters_.unmatched.load());
  stat.add("tf failures", counters_.tf_failures.load());
  stat.add("invalid inputs", counters_.invalid.load());
  stat.add("out of order", counters_.out_of_order.load());
  stat.add("processing errors", counters_.errors.load());
  stat.add("rate limited (max_rate)", counters_.rate_limited.load());
}

}  // namespace lidar_stereo_fusion
