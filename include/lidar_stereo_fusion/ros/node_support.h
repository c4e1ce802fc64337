// Pieces shared by the three parts of the live node (input gate, worker, output publisher): the
// node parameters (node_params.h), the cumulative counters, the throttled log and the input topic
// names.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <ros/node_handle.h>
#include <ros/time.h>

#include "lidar_stereo_fusion/ros/node_params.h"

namespace lidar_stereo_fusion {

/// Input topics, relative to the node handle (remappable).
constexpr const char* kLeftImage = "left/image_rect_color";
constexpr const char* kLeftInfo = "left/camera_info";
constexpr const char* kRightImage = "right/image_rect_color";
constexpr const char* kRightInfo = "right/camera_info";
constexpr const char* kCloud = "velodyne_points";

/// The node's input names (the five above) and output names (relative to its namespace; image
/// outputs also have image_transport's sub-topics, e.g. depth/image_rect/compressed): what a
/// remap may name.
const std::vector<std::string>& inputNames();
const std::vector<std::string>& outputNames();

/// The name of `names` nearest to `name`: the one name it begins or that begins with it
/// ("left/image_rect" -> "left/image_rect_color"), else the nearest by edit distance when that
/// differs in at most a third of its characters ("velodyne_point" -> "velodyne_points"); "" when
/// none is that near.
std::string nearestName(const std::string& name, const std::vector<std::string>& names);

/// The remappings (`from` -> `to`, as ROS keeps them: resolved) that name nothing of the node:
/// a `from` that is none of inputNames() / outputNames() (or an output's image_transport
/// sub-topic) resolved by `resolve` (the node handle's resolveName without remapping), nor in the
/// node's private namespace `private_ns`, nor a global name of ROS itself (/tf, /tf_static,
/// /clock, /rosout, /diagnostics). One text per such remap, naming it, the node's names and the
/// nearest one: ROS ignores such a remap, so a typo would leave an input at its default.
std::vector<std::string> unknownRemaps(const std::map<std::string, std::string>& remaps,
                                       const std::string& node_namespace,
                                       const std::string& private_ns);

/// A copy of the counters at one moment (FusionStats, diagnostics).
struct CounterSnapshot {
  uint32_t processed = 0, dropped = 0, unmatched = 0, tf_failures = 0, invalid = 0,
           out_of_order = 0, errors = 0, rate_limited = 0, motion_failures = 0;
  uint32_t problems() const {
    return dropped + unmatched + tf_failures + invalid + out_of_order + errors + motion_failures;
  }
};

/// Cumulative counters, written by every part without a lock.
struct Counters {
  std::atomic<uint32_t> processed{0}, dropped{0}, unmatched{0}, tf_failures{0}, invalid{0},
      out_of_order{0}, errors{0}, rate_limited{0}, motion_failures{0};
  CounterSnapshot snapshot() const;
};

/// Logs at most once per `period` for each (topic, kind): `kind` is a fixed word naming the kind
/// of problem, never text that varies, so one problem does not hide another and a message with a
/// changing number is still throttled. The key set is bounded (cleared beyond kMaxKeys).
class ThrottledLog {
 public:
  enum class Level { kInfo, kWarn, kError };
  static constexpr std::size_t kMaxKeys = 64;

  /// `period` [s]: wall time within which a (topic, kind) is logged once (NodeParams default).
  explicit ThrottledLog(std::string name, double period = NodeParams().log_throttle_period)
      : name_(std::move(name)), period_(period) {}
  void log(Level level, const std::string& topic, const std::string& kind, const std::string& text);
  void warn(const std::string& topic, const std::string& kind, const std::string& text) {
    log(Level::kWarn, topic, kind, text);
  }
  /// The decision alone (tests): true when (topic, kind) was not logged within the period before
  /// `now`, which is then recorded.
  bool shouldLog(const std::string& topic, const std::string& kind, const ros::WallTime& now);
  std::size_t keys() const;
  const std::string& name() const { return name_; }

 private:
  std::string name_;
  double period_;
  mutable std::mutex mutex_;  ///< the one lock: last_
  std::map<std::string, ros::WallTime> last_;
};

/// Seconds with 6 decimals, for log messages.
std::string stampText(const ros::Time& t);

}  // namespace lidar_stereo_fusion
