// The node's rate keeper (node parameter keep_rate). On a host too slow for the preset the worker
// is still busy when the next input set arrives, and sets are dropped (FusionStats.dropped_frames):
// the node publishes every second sweep. The governor then gives up search where the LiDAR has
// nothing, one step at a time, and takes the steps back once the frames would fit again.
//
// Why there: most of PatchMatch's cost evaluations on a KITTI frame go to pixels without
// scan-line bounds, above the LiDAR's top beam; inside the LiDAR's view the prior leads and the
// results hardly change (figures: doc/performance.md, "keep_rate"). The steps, each faster than
// the one before, where the levels between the coarsest and full size only propagate (`live`):
//   1. one more coarse level (coarse_levels + 1: `live` starts at 1/8 size instead of 1/4): the
//      levels it hands to only propagate; the LiDAR's view comes out the same or better (KITTI
//      ring hold-outs), above the LiDAR coarser;
//   2. back to the configured levels, pixels without bounds searched no finer than the next
//      coarser level (unbounded_scale times coarse_scale); then again one more level; and so on
//      up to the configured coarsest level;
//   3. where no level can be added (coarse_levels at its maximum), the coarsest level sweeps the
//      left view once (iterations 1).
// `live`, KITTI frame 0: 1.00x SGBM (ring hold-out 999 mm, Middlebury lower 2/3 0.343 px), one
// more level 0.80x (983 mm, 0.431 px), pixels without bounds at 1/4 0.74x (1024 mm, 0.486 px),
// both 0.58x (994 mm, 0.586 px).
// Where a level between refines its right view (intermediate_refine, the default preset), the
// first step gives that up; then pixels without bounds are searched ever coarser, and last one
// more level is added (or one sweep): the default 2.2x SGBM (synthetic street, error above the
// LiDAR 0.45 m), 1.8x (0.50 m), 1.5x (0.76 m), 1.3x (1.24 m), 1.1x (2.2 m).
//
// ROS-free (test/ros/test_rate_governor.cpp); the worker (fusion_worker.cpp) feeds it once per
// processed frame and applies params().
#pragma once

#include <deque>
#include <string>
#include <vector>

#include "lidar_stereo_fusion/core/pipeline.h"

namespace lidar_stereo_fusion {

/// One step of search effort: what PatchMatch runs with.
struct EffortStep {
  int coarse_levels = 1;    ///< reduced levels of the coarse start
  int coarsest_scale = 1;   ///< their coarsest level's reduction (coarse_scale^coarse_levels)
  int unbounded_scale = 1;  ///< the finest level searching pixels without scan-line bounds
  int iterations = 1;       ///< sweeps of the coarsest level
  /// false: the levels between the coarsest and the finest only propagate, also where the base
  /// refines there (PatchMatchParams::intermediate_refine); true: as the base.
  bool refine_between = true;
  /// E.g. "search from 1/8 size, pixels without scan-line bounds searched down to 1/4 size, 2
  /// sweeps at the coarsest level" (and, where refine_between is false, ", the right view not
  /// refined between the coarsest level and full size").
  std::string describe() const;
};

/// The steps for `base`: its own search first (pixels without bounds searched down to the finer
/// of unbounded_scale and search_scale, u), then the same with one more coarse level (unless
/// base has PatchMatchParams::kMaxCoarseLevels), then u times coarse_scale with base's levels and
/// with one more, and so on up to base's coarsest level (coarse_scale^coarse_levels); without the
/// added level, last one sweep at the coarsest level if base has more. A base whose levels
/// between refine (intermediate_refine, coarse_levels >= 2) instead gives that up first, then
/// takes u times coarse_scale up to its coarsest level, then one more level (or one sweep). A
/// method that is not fused (no scan-line bounds to search by) or a base without coarse levels
/// has one step. (A level is only added where the image is large enough,
/// PatchMatchStereo::compute: on a small image such a step costs what the one before did.)
std::vector<EffortStep> effortSteps(const FusionParams& base);

class RateGovernor {
 public:
  static constexpr int kWindow = 10;        ///< frames judged together
  static constexpr int kLateFrames = 2;     ///< frames of a window followed by drops: step down
  static constexpr int kCalmFrames = 100;   ///< frames in a row without drops before a step up
  static constexpr double kHeadroom = 0.8;  ///< step up when predicted <= this share of a period

  explicit RateGovernor(const FusionParams& base) { rebase(base); }

  /// After each processed frame: `dropped` input sets dropped since the previous call (the worker
  /// was busy when a newer one came), the input `period` [s] (InputGate::inputPeriod; 0 = not
  /// known: no step up) and the worker's time on the frame `busy_ms`. Returns true when the step
  /// changed; params() is then what the next frame uses and reason() says why.
  bool observe(unsigned dropped, double period, double busy_ms);

  /// The configured parameters with the current step's search (at the first step, as configured).
  FusionParams params() const;
  /// The parameters changed (dynamic_reconfigure): the steps follow them, from the first.
  void rebase(const FusionParams& base);

  int step() const { return step_; }
  int steps() const { return static_cast<int>(steps_.size()); }
  const EffortStep& current() const { return steps_[static_cast<size_t>(step_)]; }
  const std::string& reason() const { return reason_; }

 private:
  void changeStep(int step, const std::string& why);
  static double median(std::vector<double> v);

  FusionParams base_;
  std::vector<EffortStep> steps_;
  int step_ = 0;
  std::deque<bool> late_;        ///< the last kWindow frames at this step: followed by drops
  std::deque<double> busy_;      ///< their busy times [ms]
  std::vector<double> leaving_;  ///< per step: median busy time when it was left for the next
  std::vector<double> arrived_;  ///< per step: median busy time of its first window
  int calm_ = 0;                 ///< frames in a row without drops at this step
  std::string reason_;
};

}  // namespace lidar_stereo_fusion
