// The dense-LiDAR accuracy protocol: KITTI raw drive 0009, frame 20, the full sweep (64 rings,
// rings recovered from the sweep order as kitti::loadFrame does) fed to every method, scored
// against the depth accumulated from sweeps 15-25 (eval/kitti_accumulated.h: OXTS poses, points
// that disagree with frame 20's own sweep removed, frame 20's own sweep included, as in KITTI's
// depth-completion ground truth). Empty pixels are filled like the devkit (fillLikeDevkit) before
// scoring, as in the other protocols. Regions as eval/accuracy_protocols.h (above / inside / edge /
// elsewhere from the fed projection) plus the depth bands < 10 m, 10-30 m, >= 30 m of the
// reference depth. ROS-free.
#pragma once

#include "lidar_stereo_fusion/eval/accuracy_protocols.h"
#include "lidar_stereo_fusion/eval/kitti_accumulated.h"
#include "lidar_stereo_fusion/eval/stereo_check.h"

namespace lidar_stereo_fusion {

/// The frame of the dense protocol (the drive's frame with 5 sweeps and OXTS packets each side).
constexpr const char* kDenseFrame = "0000000020";

/// The layout "dense" and how its reference was built.
struct DenseProtocolResult {
  LayoutScores<DepthMetrics> layout;
  kitti::AccumulatedDepth reference;  ///< after the stereo check, if one ran
  StereoCheckCounts stereo_check;     ///< all 0 without one
};

/// Runs the dense protocol on data_dir/kitti_raw/2011_09_26/2011_09_26_drive_0009_sync (every
/// wanted row; pms and "lidar_bi else pms" only when options.kitti_pms). Throws
/// std::runtime_error naming what is missing (the drive, a sweep, an OXTS packet, the frame's
/// images). With stereo_check_px > 0 the reference keeps only the pixels where SGBM of the
/// frame's pair agrees within that many pixels (removeStereoOutliers; KITTI's ground truth is
/// cleaned with stereo likewise).
DenseProtocolResult runDenseProtocol(const AccuracyOptions& options,
                                     const kitti::AccumulationParams& reference_params = {},
                                     double stereo_check_px = 0.0);

}  // namespace lidar_stereo_fusion
