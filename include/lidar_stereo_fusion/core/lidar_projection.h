// Stage 1: projection of a LiDAR sweep into a rectified view as sparse disparity (paper Eq. 1-2).
// The scan-line (ring) recovery for clouds that carry none is in core/ring_recovery.h (included
// here, since every user of a projected ring map needs it).
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/ring_recovery.h"
#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {

struct ProjectionParams {
  double min_depth = 0.5;    ///< points closer than this [m] (along the optical axis) are dropped
  double max_depth = 200.0;  ///< points farther than this [m] are dropped
  /// Drop the points the left camera cannot see beside near objects before projecting
  /// (removePointsHiddenBeside; an ego-motion compensated sweep always gets it).
  bool remove_hidden_beside = false;
  void validate() const;
};

/// Which rectified view to project into. Right-view pixels are left pixels shifted by -d.
enum class View { kLeft, kRight };

/// Sparse LiDAR disparity in one view.
struct SparseDisparity {
  cv::Mat1f disparity;        ///< [px], 0 = no point (z-buffer: nearest point kept per pixel)
  cv::Mat1s ring;             ///< ring index of the kept point, -1 where empty or unknown
  int points_in_front = 0;    ///< points with min_depth <= z <= max_depth
  int points_in_image = 0;    ///< of those, points that landed inside the image
  int points_not_finite = 0;  ///< points skipped because x, y or z is NaN / inf
};

/// Projects `cloud` with the rigid transform `T_cam_lidar` (LiDAR frame -> left optical frame)
/// into `view`; d = fx * B / z [px] with z [m] along the left optical axis. Sub-pixel coordinates
/// are rounded to the nearest pixel, pixel i covering [i - 0.5, i + 0.5) (i = floor(u + 0.5)).
/// In the right view the sub-pixel column is u_left - d, rounded by the same rule; the stored value
/// is the same (positive) disparity d. Non-finite points and points outside
/// [min_depth, max_depth] are skipped; the nearest point (largest d) wins a pixel, ties keep the
/// first point of the cloud. Points with ring < 0 get ring -1 in the ring map.
/// Throws std::invalid_argument for an invalid camera, params, a non-finite or non-rigid transform,
/// or a ring index above 32767.
SparseDisparity projectCloud(const LidarCloud& cloud, const Eigen::Isometry3d& T_cam_lidar,
                             const StereoCamera& camera, const ProjectionParams& params,
                             View view = View::kLeft);

}  // namespace lidar_stereo_fusion
