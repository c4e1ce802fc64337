#include "lidar_stereo_fusion/ros/node_support.h"

#include <algorithm>
#include <iomanip>
#include <sstream>

#include <ros/console.h>
#include <ros/names.h>

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

const std::vector<std::string>& inputNames() {
  static const std::vector<std::string> kNames = {kLeftImage, kLeftInfo, kRightImage, kRightInfo,
                                                  kCloud};
  return kNames;
}

const std::vector<std::string>& outputNames() {
  // As OutputPublisher::advertise() names them (depth/camera_info with depth/image_rect).
  static const std::vector<std::string> kNames = {
      "depth/image_rect", "depth/camera_info", "depth/image_color",     "disparity",  "points2",
      "lidar_disparity",  "disparity_image",   "disparity_image_color", "confidence", "stats"};
  return kNames;
}

namespace {

/// Levenshtein distance (names are short: the full table is cheap).
std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::string joinedNames(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace

std::string nearestName(const std::string& name, const std::vector<std::string>& names) {
  // A name cut short or run on ("left/image_rect" for "left/image_rect_color") first.
  std::vector<std::string> extended;
  for (const auto& candidate : names) {
    if (!name.empty() && (candidate.rfind(name, 0) == 0 || name.rfind(candidate, 0) == 0)) {
      extended.push_back(candidate);
    }
  }
  if (extended.size() == 1) return extended.front();
  std::string best;
  std::size_t best_distance = name.size() / 3 + 1;  // more than a third differs: no suggestion
  for (const auto& candidate : names) {
    const std::size_t d = editDistance(name, candidate);
    if (d < best_distance) {
      best_distance = d;
      best = candidate;
    }
  }
  return best;
}

std::vector<std::string> unknownRemaps(const std::map<std::string, std::string>& remaps,
                                       const std::string& node_namespace,
                                       const std::string& private_ns) {
  std::vector<std::string> known;  // resolved
  for (const auto* list : {&inputNames(), &outputNames()}) {
    for (const auto& n : *list) known.push_back(ros::names::resolve(node_namespace, n, false));
  }
  const std::vector<std::string> ros_names = {"/tf", "/tf_static", "/clock", "/rosout",
                                              "/diagnostics"};
  const std::string private_prefix = private_ns + "/";
  std::vector<std::string> problems;
  for (const auto& [from, to] : remaps) {
    if (std::find(known.begin(), known.end(), from) != known.end()) continue;
    if (std::find(ros_names.begin(), ros_names.end(), from) != ros_names.end()) continue;
    if (from.rfind(private_prefix, 0) == 0) continue;
    const bool transport_topic = std::any_of(known.begin(), known.end(), [&](const auto& k) {
      return from.rfind(k + "/", 0) == 0;  // an output's image_transport sub-topic
    });
    if (transport_topic) continue;
    std::vector<std::string> relative;  // the node's names, to suggest the nearest
    for (const auto* list : {&inputNames(), &outputNames()}) {
      relative.insert(relative.end(), list->begin(), list->end());
    }
    const std::string ns_prefix = node_namespace == "/" ? "/" : node_namespace + "/";
    const std::string short_from =
        from.rfind(ns_prefix, 0) == 0 ? from.substr(ns_prefix.size()) : from;
    const std::string nearest = nearestName(short_from, relative);
    problems.push_back(
        "remap " + from + " := " + to + " names no topic of this node, so ROS ignores it" +
        (nearest.empty() ? "" : " (did you mean " + nearest + "?)") +
        "; its inputs: " + joinedNames(inputNames()) +
        "; its outputs: " + joinedNames(outputNames()) + " (in " + node_namespace + ")");
  }
  return problems;
}

std::string stampText(const ros::Time& t) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(6) << t.toSec();
  return s.str();
}

}  // namespace lidar_stereo_fusion
