// A KITTI-style accumulated depth reference: the sweeps around a target frame, moved into the
// target's left camera with the OXTS poses, z-buffered into the left image, with the points that
// disagree with the target's own sweep removed. ROS-free.
//
// KITTI's depth-completion ground truth (Uhrig et al., "Sparsity Invariant CNNs", 3DV 2017) is
// built the same way from 11 sweeps (the frame's own and 5 on each side), with outliers removed
// against a stereo reconstruction; here they are removed against the target's own sweep instead
// (the rule is accumulateDepth's). The reference includes the target's own sweep, as KITTI's does.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/types.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/kitti_oxts.h"

namespace lidar_stereo_fusion {
namespace kitti {

/// How the reference is accumulated and checked.
struct AccumulationParams {
  int half_span = 5;  ///< sweeps target - half_span .. target + half_span (KITTI: 5, 11 sweeps)
  double min_depth = 0.5;    ///< [m] points nearer than this (along the optical axis) are dropped
  double max_depth = 120.0;  ///< [m] farther points are dropped (the HDL-64E's range)
  /// A point of another sweep is kept only when the target's own sweep has a point within
  /// +-check_half_width columns and +-check_half_height rows of its pixel, and its depth z lies in
  /// [z_min (1 - tolerance), z_max (1 + tolerance)] of those points' depths.
  int check_half_width = 2;   ///< [px]
  int check_half_height = 3;  ///< [px] (the HDL-64E's rings are 4-6 rows apart in KITTI's image)
  double tolerance = 0.05;    ///< relative depth tolerance [-]
  /// Keep the points without an own point in the window (they are counted as removed_unverified
  /// all the same); for measuring what the rule's first half removes.
  bool keep_unverified = false;
  /// How the kept points of a pixel make its reference depth. kNearest (the default, a z-buffer):
  /// the nearest. kMajority: each sweep's nearest point in the pixel is one vote; the depth most
  /// sweeps agree on (the largest group within `tolerance` of its nearest member; between equal
  /// groups the nearer) wins, as the group's median. Near a depth edge the sweeps' points scatter
  /// by a pixel or so (poses, rounding), and the nearest of up to 11 favours the foreground there
  /// (doc/accuracy.md, "who is right at depth edges").
  enum class Combine { kNearest, kMajority };
  Combine combine = Combine::kNearest;
  /// Throws std::invalid_argument naming the first impossible value.
  void validate() const;
};

/// One sweep expressed in the target's left camera frame.
struct PosedSweep {
  std::string name;               ///< frame, e.g. "0000000017"
  LidarCloud cloud;               ///< [m], Velodyne frame of that sweep
  Eigen::Isometry3d T_cam_lidar;  ///< that sweep's Velodyne frame -> the target's left camera
  bool own = false;               ///< the target frame's own sweep
};

/// The reference and what building it did.
struct AccumulatedDepth {
  cv::Mat1f depth;  ///< [m], 0 = no reference; nearest point per pixel (z-buffer)
  cv::Mat1b own;    ///< 255 where the target's own sweep has a point (it may lose the z-buffer)
  int sweeps = 0;   ///< sweeps accumulated, the own one included
  long other_points = 0;         ///< points of the other sweeps that land in the image in range
  long removed_unverified = 0;   ///< of those: no own point in the check window
  bool unverified_kept = false;  ///< AccumulationParams::keep_unverified: those were kept
  long removed_disagreeing = 0;  ///< of those: depth outside the window's own depth range
  int own_pixels = 0;            ///< pixels of the own sweep alone
  int pixels = 0;                ///< pixels of the reference
  /// Where both the own sweep and the other sweeps' z-buffer (before any removal) have a point:
  /// the median and 90th percentile of |z_other - z_own| / z_own, and how many such pixels.
  double median_relative_difference = 0, p90_relative_difference = 0;
  int compared_pixels = 0;
};

/// Accumulates `sweeps` (exactly one of them `own`) into the left image of `camera`: every finite
/// point with min_depth <= z <= max_depth is projected (pixel = round(fx x / z + cx), round(fy y /
/// z + cy), as projectCloud), the own sweep's points as they are, each other sweep's point only
/// when it agrees with the own sweep by the window rule of AccumulationParams; the nearest point
/// wins a pixel (or the majority of the sweeps, AccumulationParams::combine). Throws
/// std::invalid_argument for an invalid camera or params, or when not exactly one sweep is `own`.
AccumulatedDepth accumulateDepth(const std::vector<PosedSweep>& sweeps, const StereoCamera& camera,
                                 const AccumulationParams& params);

/// The sweeps target - half_span .. target + half_span of `drive_dir` (Velodyne .bin and OXTS
/// packet each, the sweeps as recorded), posed into the target's left camera with the
/// devkit's OXTS poses and calib_imu_to_velo.txt: T_cam_lidar = T_cam_velo T_velo_imu
/// P_target^-1 P_k T_velo_imu^-1. Throws std::runtime_error naming a missing sweep, packet or
/// stamp.
std::vector<PosedSweep> loadPosedSweeps(const std::string& drive_dir, const std::string& target,
                                        const Calibration& calib, const AccumulationParams& params);

/// loadPosedSweeps + accumulateDepth with the calibration's left camera.
AccumulatedDepth buildAccumulatedReference(const std::string& drive_dir, const std::string& target,
                                           const Calibration& calib,
                                           const AccumulationParams& params = {});

}  // namespace kitti
}  // namespace lidar_stereo_fusion
