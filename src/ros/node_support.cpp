#include "lidar_stereo_fusion/ros/node_support.h"

#include <iomanip>
#include <sstream>

#include <ros/console.h>

namespace lidar_stereo_fusion {

namespace {

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
  readChecked(pnh, "depth_color_max", p.depth_color_max, positive, "must be > 0 [m]");
  readChecked(pnh, "max_rate", p.max_rate, non_negative, "must be >= 0 [Hz] (0 = no limit)");
  readChecked(
      pnh, "fresh_wait", p.fresh_wait, [](double v) { return v >= 0.0 && v <= 1.0; },
      "must be in [0, 1] s (0 = off)");
  readChecked(pnh, "input_timeout", p.input_timeout, non_negative, "must be >= 0 [s] (0 = off)");
  readChecked(
      pnh, "log_throttle_period", p.log_throttle_period,
      [](double v) { return v >= 0.0 && v <= 3600.0; }, "must be in [0, 3600] s (0 = every line)");
  readChecked(
      pnh, "worker_nice", p.worker_nice, [](int v) { return v >= 0 && v <= 19; },
      "must be in [0, 19]");
  readChecked(pnh, "fixed_frame", p.fixed_frame, any, "");
  readChecked(
      pnh, "motion_samples", p.motion_samples, [](int v) { return v >= 1 && v <= 100; },
      "must be in [1, 100]");
  readChecked(
      pnh, "motion_failure", p.motion_failure,
      [](const std::string& v) { return v == "uncompensated" || v == "skip"; },
      "must be 'uncompensated' or 'skip'");
  readChecked(
      pnh, "max_point_time", p.max_point_time, [](double v) { return v > 0.0 && v <= 10.0; },
      "must be in (0, 10] s");
  readChecked(pnh, "diagnostics/min_rate", p.diag_min_rate, non_negative, "must be >= 0 [Hz]");
  readChecked(pnh, "diagnostics/max_rate", p.diag_max_rate, positive, "must be > 0 [Hz]");
  readChecked(pnh, "diagnostics/max_latency", p.diag_max_latency, positive, "must be > 0 [s]");
  return p;
}

CounterSnapshot Counters::snapshot() const {
  CounterSnapshot s;
  s.processed = processed;
  s.dropped = dropped;
  s.unmatched = unmatched;
  s.tf_failures = tf_failures;
  s.invalid = invalid;
  s.out_of_order = out_of_order;
  s.errors = errors;
  s.rate_limited = rate_limited;
  s.motion_failures = motion_failures;
  return s;
}

bool ThrottledLog::shouldLog(const std::string& topic, const std::string& kind,
                             const ros::WallTime& now) {
  const std::string key = topic + '|' + kind;
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = last_.find(key);
  if (it != last_.end() && (now - it->second).toSec() < period_) return false;
  // Topics and kinds are fixed words, so this does not happen in the node; it bounds the map
  // whatever a caller passes.
  if (it == last_.end() && last_.size() >= kMaxKeys) last_.clear();
  last_[key] = now;
  return true;
}

std::size_t ThrottledLog::keys() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_.size();
}

void ThrottledLog::log(Level level, const std::string& topic, const std::string& kind,
                       const std::string& text) {
  if (!shouldLog(topic, kind, ros::WallTime::now())) return;
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

std::string stampText(const ros::Time& t) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(6) << t.toSec();
  return s.str();
}

}  // namespace lidar_stereo_fusion
