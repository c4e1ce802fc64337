// Scoring Algorithm 1 (removal of occluded LiDAR points) against the generator's exact
// visibility flags.
#pragma once

#include "lidar_stereo_fusion/core/upsampling.h"
#include "lidar_stereo_fusion/sim/synthetic_frame.h"

namespace lidar_stereo_fusion {
namespace sim {

/// Counts over the LiDAR points that are scan-line pixels before Algorithm 1: the point wins its
/// left-image pixel in the z-buffer and `before` holds its disparity there. Each pixel is counted
/// once.
struct OcclusionRemovalScore {
  int occluded = 0;          ///< such points the left camera cannot see (PointTruth::visible false)
  int occluded_removed = 0;  ///< of those, pixels that `after` cleared
  int visible = 0;           ///< such points the left camera sees
  int visible_kept = 0;      ///< of those, pixels `after` still holds
  double removedFraction() const { return occluded ? double(occluded_removed) / occluded : 0.0; }
  double keptFraction() const { return visible ? double(visible_kept) / visible : 0.0; }
};

/// Compares scan lines `before` and `after` removeOccludedPoints (left view of `frame`).
/// Throws std::invalid_argument when the maps do not have the frame's image size.
OcclusionRemovalScore scoreOcclusionRemoval(const SyntheticFrame& frame, const ScanLines& before,
                                            const ScanLines& after);

}  // namespace sim
}  // namespace lidar_stereo_fusion
