// The moving synthetic rig: the street driven at a given speed, the sweep taken while the rig
// moves and at an offset from the images (SyntheticParams::moving_sweep), and what ego-motion
// compensation gives back. Scores the methods in the LiDAR's field of view against the exact
// ground truth at the image instant.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "lidar_stereo_fusion/core/motion_compensation.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/sim/synthetic_frame.h"

namespace lidar_stereo_fusion {
namespace sim {

/// The rig's motion over the frame's sweep, to the image instant, as the nodelet samples it from
/// TF (`samples` instants over the points' time span): the street scene's rig drives straight at
/// params.speed, so this is constantVelocityMotion with the velocity in the LiDAR frame.
SweepMotion frameMotion(const SyntheticFrame& frame, const SyntheticParams& params,
                        int samples = 5);

/// One row of the moving-rig table: a method at one speed and LiDAR offset.
struct MovingRigRow {
  std::string method;
  double speed = 0;   ///< [m/s]
  double offset = 0;  ///< [s] SyntheticParams::lidar_time_offset
  /// How the sweep was taken and fed: "still" (cast at once from the image instant's pose: the
  /// static reference at the same place), "as taken" (while moving) or "compensated" (frameMotion).
  std::string sweep;
  double mae_px = 0;        ///< disparity MAE in the LiDAR's field of view [px]
  double bad3 = 0;          ///< fraction of those pixels with an error > 3 px
  double prior_mae_px = 0;  ///< the same for the projected LiDAR points alone (sparse)
};

/// For each speed, renders frames 1..`frames` of the street with the sweep taken at the image
/// instant (the reference), then for each offset with the sweep taken while moving
/// (moving_sweep), and runs every method on the reference, the sweep as taken and compensated;
/// the scores are means over the frames. Empty pixels are filled like the KITTI
/// devkit before scoring. `methods`: (name, parameters).
std::vector<MovingRigRow> runMovingRig(
    const SyntheticParams& base, const std::vector<double>& speeds,
    const std::vector<double>& offsets,
    const std::vector<std::pair<std::string, FusionParams>>& methods, int frames = 1);

/// The rows as a Markdown table.
std::string formatMovingRig(const std::vector<MovingRigRow>& rows);

}  // namespace sim
}  // namespace lidar_stereo_fusion
