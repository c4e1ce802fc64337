// The node's parameters (the ROS layer's, not the algorithm's) and their table: the same row type
// as the algorithm's table (core/param_table.h), read by the same rosparam and YAML readers,
// checked by the same rangeProblem(), listed in the same generated files (config/fusion_node.yaml,
// cfg/Fusion.cfg for the rows marked Live::kYes, doc/parameters.md).
//
// This header includes no ROS: bag_runner and the docs generator use it as well.
#pragma once

#include <string>
#include <type_traits>
#include <vector>

#include "lidar_stereo_fusion/core/param_spec.h"

namespace lidar_stereo_fusion {

struct ParamInfo;  // io/param_table.h

/// Parameters of the ROS layer (the nodelet's private namespace; bag_runner --node-params).
struct NodeParams {
  bool approximate_sync = false;
  int queue_size = 5;
  double max_time_offset = 0.1;  ///< [s]
  double max_sweep_wait = 0.3;   ///< [s] ROS time (sim time aware)
  int sweep_buffer_size = 10;
  double max_rate = 0.0;     ///< [Hz] 0 = no limit (dropped sets: FusionStats.rate_limited)
  double fresh_wait = 0.05;  ///< [s] FreshWait; 0 = always the newest waiting set at once
  bool keep_rate = false;    ///< rate_governor.h
  double tf_timeout = 0.05;  ///< [s] worker thread only
  std::string fixed_frame;   ///< ego-motion compensation through this frame; empty = off
  int motion_samples = 5;
  std::string motion_failure = "uncompensated";
  double max_point_time = 0.2;  ///< [s]
  int num_rings = 64;           ///< ring recovery (ensureRings)
  int cloud_stride = 1;
  double max_output_depth = 0.0;     ///< [m] 0 = no limit
  double depth_color_max = 80.0;     ///< [m]
  double input_timeout = 5.0;        ///< [s] wall time; 0 = off
  double log_throttle_period = 5.0;  ///< [s] wall time (ThrottledLog); tests set it short
  int worker_nice = 10;
  bool keep_freed_memory = true;  ///< io/process_memory.h
  double diag_min_rate = 1.0;     ///< [Hz]
  double diag_max_rate = 100.0;   ///< [Hz]
  double diag_max_latency = 2.0;  ///< [s]

  /// Throws std::invalid_argument("NodeParams: <name> must be ...") at the first value outside
  /// its row's range or choices, or when the diagnostics' rates are the wrong way round.
  void validate() const;
};

/// Every row with its default as text, in table order (io/param_table.h's ParamInfo).
std::vector<ParamInfo> nodeParamTable();

/// Node parameters from a YAML file in the layout of config/fusion_node.yaml (bag_runner
/// --node-params): keys not in the file keep their defaults. Throws std::runtime_error naming the
/// file and the key: unknown key, wrong type, value out of range.
NodeParams readNodeParamsYaml(const std::string& path);

/// Calls v(ParamSpec, field&) for every row, in the order of config/fusion_node.yaml.
template <class P, class V>
std::enable_if_t<std::is_same_v<std::decay_t<P>, NodeParams>> visitParams(P&& p, V&& v) {
  constexpr Live kStartup = Live::kStartup;  // read once: the synchroniser and threads use them
  const char* g = "sync";
  v(ParamSpec{"approximate_sync",
              g,
              {},
              "",
              "ApproximateTime instead of ExactTime for the image set (stamps differ, e.g. KITTI)",
              "",
              kStartup},
    p.approximate_sync);
  v(ParamSpec{"queue_size", g, atLeast(1), "", "Synchroniser queue per topic", "", kStartup},
    p.queue_size);
  v(ParamSpec{"max_time_offset", g, atLeast(0), "s",
              "Largest |sweep stamp - image stamp| of a matched set", "", kStartup},
    p.max_time_offset);
  v(ParamSpec{"max_sweep_wait", g, atLeast(0), "s",
              "ROS time an image set waits for a sweep stamped at or after it", "", kStartup},
    p.max_sweep_wait);
  v(ParamSpec{"sweep_buffer_size", g, atLeast(1), "", "Recent sweeps kept for matching", "",
              kStartup},
    p.sweep_buffer_size);
  v(ParamSpec{"max_rate", g, atLeast(0), "Hz",
              "Image sets closer than 0.9 / max_rate after the last one are dropped (0 = no limit)",
              "", kStartup},
    p.max_rate);
  v(ParamSpec{"fresh_wait", g, within(0, 1), "s",
              "A free worker waits this long for the next due set instead of an older one (0 = "
              "off)",
              "", kStartup},
    p.fresh_wait);
  v(ParamSpec{"keep_rate",
              g,
              {},
              "",
              "When input sets are dropped because the worker is busy, search less, mostly "
              "above the LiDAR (no right-view refinement between levels, one more coarse "
              "level, pixels without scan-line bounds at a coarser level) until the frames fit "
              "the input's rate again; warned and in "
              "diagnostics (true in fusion.launch with preset:=live)",
              "",
              kStartup},
    p.keep_rate);
  g = "motion";
  v(ParamSpec{"tf_timeout", g, within(0, 10), "s",
              "LiDAR -> camera (and ego-motion) TF lookup timeout; the frame is skipped after it"},
    p.tf_timeout);
  v(ParamSpec{"fixed_frame",
              g,
              {},
              "",
              "Ego-motion compensation through this frame of TF, e.g. odom (empty = off)"},
    p.fixed_frame);
  v(ParamSpec{"motion_samples", g, within(1, 100), "",
              "TF lookups per sweep, evenly over its point times"},
    p.motion_samples);
  v(ParamSpec{"motion_failure",
              g,
              {},
              "",
              "A frame whose ego-motion TF is missing: processed uncompensated, or skipped",
              "uncompensated|skip"},
    p.motion_failure);
  v(ParamSpec{"max_point_time", g, aboveUpTo(0, 10), "s",
              "Per-point times farther from the stamp, or NaN, are named and not used"},
    p.max_point_time);
  v(ParamSpec{"num_rings", g, within(1, 4096), "",
              "Beams of the LiDAR, for clouds without a ring field (rings by elevation)"},
    p.num_rings);
  g = "outputs";
  v(ParamSpec{"cloud_stride", g, within(1, 64), "",
              "points2 keeps every k-th pixel in rows and columns"},
    p.cloud_stride);
  v(ParamSpec{"max_output_depth", g, atLeast(0), "m",
              "Depth and points2 beyond this are empty (0 = no limit)"},
    p.max_output_depth);
  v(ParamSpec{"depth_color_max", g, above(0), "m", "Far end of depth/image_color's colour scale"},
    p.depth_color_max);
  g = "monitoring";
  v(ParamSpec{"input_timeout", g, atLeast(0), "s",
              "An input silent this long while outputs are subscribed is warned about (0 = off)",
              "", kStartup},
    p.input_timeout);
  v(ParamSpec{"log_throttle_period", g, within(0, 3600), "s",
              "A warning of one kind on one topic is repeated at most once per this (0 = every "
              "line)",
              "", kStartup},
    p.log_throttle_period);
  v(ParamSpec{"worker_nice", g, within(0, 19), "",
              "Nice increment of the processing thread and its OpenMP threads", "", kStartup},
    p.worker_nice);
  v(ParamSpec{"keep_freed_memory",
              g,
              {},
              "",
              "Freed memory stays with the process (glibc mallopt): each frame reuses the pages of "
              "the last instead of faulting new ones in (about 4 ms a KITTI frame); the manager's "
              "resident size stays near its peak",
              "",
              kStartup},
    p.keep_freed_memory);
  v(ParamSpec{"diagnostics/min_rate", g, atLeast(0), "Hz",
              "Diagnostics: output rate below this is a warning (while subscribed)", "", kStartup},
    p.diag_min_rate);
  v(ParamSpec{"diagnostics/max_rate", g, above(0), "Hz",
              "Diagnostics: output rate above this is a warning", "", kStartup},
    p.diag_max_rate);
  v(ParamSpec{"diagnostics/max_latency", g, above(0), "s",
              "Diagnostics: image stamp -> publish delay above this is a warning", "", kStartup},
    p.diag_max_latency);
}

}  // namespace lidar_stereo_fusion
