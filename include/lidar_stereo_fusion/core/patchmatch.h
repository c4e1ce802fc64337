// Stage 3: LiDAR-guided PatchMatch stereo with slanted support windows (Bleyer et al. 2011 with
// the LiDAR disparity term of Xu et al.). Plain PMS is the mode gamma = 0, use_lidar_bounds =
// false, init_from_prior = false.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/patchmatch/params.h"
#include "lidar_stereo_fusion/core/upsampling.h"

namespace lidar_stereo_fusion {

namespace patchmatch {
struct SearchOptions;
class PlaneSearch;
}  // namespace patchmatch

/// Runs guided PatchMatch. Scratch buffers (images as float, planes, costs) are reused across
/// calls of the same object, so a stream of same-size frames allocates nothing after the first.
/// Not thread-safe: one object per thread.
class PatchMatchStereo {
 public:
  explicit PatchMatchStereo(const PatchMatchParams& params = PatchMatchParams());
  void setParams(const PatchMatchParams& params);
  const PatchMatchParams& params() const { return configured_; }
  /// Whether compute() returns the plane maps (PatchMatchResult::planes, right_planes; the
  /// default): without them, a frame maps and allocates two full-size images less (the fusion
  /// pipeline reads the disparity alone).
  void setPlanesOutput(bool planes);

  /// left/right images must have the same size and type. Priors and bounds are optional.
  PatchMatchResult compute(const ViewInput& left, const ViewInput& right);

 private:
  PatchMatchParams configured_;  ///< as set
  PatchMatchParams params_;      ///< as the current compute() runs them (forImage())
  struct Scratch;
  std::shared_ptr<Scratch> scratch_;
  std::shared_ptr<PatchMatchStereo> coarse_;  ///< the coarse start's solver (coarse_scale > 1)
  bool intermediate_ = false;                 ///< a reduced level of another solver's coarse start
  int level_scale_ = 1;                       ///< this level's reduction from full size (steps)
  bool planes_wanted_ = true;                 ///< PatchMatchResult::planes is used
  bool right_planes_wanted_ = true;           ///< PatchMatchResult::right_planes is used
  struct Steps;
  std::shared_ptr<Steps> steps_;  ///< the current compute()'s step timer

  // compute()'s stages, in order (patchmatch.cpp): prepare the views, start from the coarse
  // start's planes, search each view (initialisation, propagation, refinement, view propagation),
  // post-process (left-right check, hole filling, weighted median).
  struct Level;
  Level prepareLevel(const ViewInput& left, const ViewInput& right, bool guided);
  /// The coarse start's level below, on the views reduced by coarse_scale; its right view's
  /// planes only if asked (`right_planes`: this level searches a right view from them).
  PatchMatchResult levelBelow(const ViewInput& left, const ViewInput& right, bool right_planes);
  /// Coarse start: the level below's planes guide this level; its left-right check decides
  /// which pixels are left to the fill (skip_inconsistent) or marked inconsistent here.
  void startFromLevelBelow(const ViewInput& left, const ViewInput& right, Level& level);
  cv::Mat1b checkLevelBelow(const PatchMatchResult& coarse, const Level& level) const;
  void skipInconsistent(const cv::Mat1b& below, const Level& level);
  void searchViews(const Level& level);
  void searchOptions(const Level& level, patchmatch::SearchOptions& left,
                     patchmatch::SearchOptions& right) const;
  /// One iteration of the right view: view propagation in, sweep, view propagation back.
  void searchRightView(const Level& level, const patchmatch::PlaneSearch& left,
                       const patchmatch::PlaneSearch& right, bool right_refines, int iteration);
  PatchMatchResult postProcess(const Level& level);
  cv::Mat1b consistencyCheck(const PatchMatchResult& result, const Level& level) const;
  /// A level that does not search (search_scale): the level below's result, up-sampled.
  PatchMatchResult upsampledResult(const ViewInput& left, const ViewInput& right);
};

}  // namespace lidar_stereo_fusion
