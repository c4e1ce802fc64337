// Pieces shared by the three parts of the live node (input gate, worker, output publisher): the
// node parameters, the cumulative counters, the throttled log and the input topic names.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>

#include <ros/node_handle.h>
#include <ros/time.h>

namespace lidar_stereo_fusion {

/// Input topics, relative to the node handle (remappable).
constexpr const char* kLeftImage = "left/image_rect_color";
constexpr const char* kLeftInfo = "left/camera_info";
constexpr const char* kRightImage = "right/image_rect_color";
constexpr const char* kRightInfo = "right/camera_info";
constexpr const char* kCloud = "velodyne_points";

/// Parameters of the ROS layer (private namespace; defaults in config/fusion_node.yaml).
struct NodeParams {
  bool approximate_sync = false;  ///< ApproximateTime instead of ExactTime for the image set
  int queue_size = 5;             ///< synchroniser queue per topic
  double max_time_offset = 0.1;   ///< [s] largest |sweep stamp - image stamp|
  double max_sweep_wait = 0.3;    ///< [s] ROS time (sim time aware) a set waits for a later sweep
  int sweep_buffer_size = 10;     ///< recent sweeps kept for matching
  double tf_timeout = 0.05;       ///< [s] LiDAR -> camera TF lookup timeout (worker thread)
  int num_rings = 64;             ///< beams of the LiDAR (ring recovery; see ensureRings)
  int cloud_stride = 1;           ///< points2 keeps every k-th pixel in rows and columns
  double max_output_depth = 0.0;  ///< [m] depth / points2 beyond this are empty (0 = no limit)
  double depth_color_max = 80.0;  ///< [m] depth/image_color: the far end of the colour scale
  /// [Hz] image sets stamped closer than 0.9 / max_rate after the last accepted one are dropped on
  /// arrival, counted (FusionStats.rate_limited) and not warned about. 0 = no limit.
  double max_rate = 0.0;
  /// [s] when the worker gets free and the next matched set is due within this (at most half the
  /// input period), it waits for that set and drops the older one: lower latency, a slightly lower
  /// output rate (FreshWait). 0 = always the newest waiting set at once.
  double fresh_wait = 0.05;
  /// [s] wall time after which an input topic that sent nothing is warned about, by name (0 = off).
  double input_timeout = 5.0;
  /// [s] wall time within which a warning of the same kind on the same topic is not repeated
  /// (ThrottledLog); tests set it short instead of outwaiting it.
  double log_throttle_period = 5.0;
  /// Nice increment of the worker thread (and so of the OpenMP threads it starts): the pipeline
  /// uses every core, and ROS callbacks, nodelet bond heartbeats and drivers in the same machine
  /// must still be served on time. 0 = same priority as the callbacks.
  int worker_nice = 10;
  /// Ego-motion compensation: the frame TF holds the rig's motion in (e.g. `odom`); every point
  /// is moved from its measurement time to the left image's stamp through it. Empty = off.
  std::string fixed_frame;
  int motion_samples = 5;  ///< TF lookups per sweep, evenly over its point times (>= 1)
  /// What a frame whose ego-motion TF is missing or stale gets: "uncompensated" (processed as
  /// without fixed_frame, counted and warned) or "skip" (counted and warned).
  std::string motion_failure = "uncompensated";
  /// [s] per-point times farther than this from the sweep's stamp, or NaN, are named, counted and
  /// not used (the point keeps the stamp's time).
  double max_point_time = 0.2;
  double diag_min_rate = 1.0;     ///< [Hz] diagnostics: lowest acceptable output rate
  double diag_max_rate = 100.0;   ///< [Hz] diagnostics: highest acceptable output rate
  double diag_max_latency = 2.0;  ///< [s] diagnostics: largest acceptable stamp -> publish delay

  /// Reads the parameters present under `pnh`; a wrong type or impossible value is logged as an
  /// error naming the parameter and the default is kept.
  static NodeParams read(const ros::NodeHandle& pnh);
};

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
