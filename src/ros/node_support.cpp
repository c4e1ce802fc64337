#include "lidar_stereo_fusion/ros/node_support.h"

#include <iomanip>
#include <sstream>

#include <ros/console.h>

namespace lidar_stereo_fusion {

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
