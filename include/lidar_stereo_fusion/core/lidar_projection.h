// Stage 1: projection of a LiDAR sweep into a rectified view as sparse disparity (paper Eq. 1-2),
// and recovery of scan-line (ring) indices for clouds that carry none.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {

struct ProjectionParams {
  double min_depth = 0.5;    ///< points closer than this [m] (along the optical axis) are dropped
  double max_depth = 200.0;  ///< points farther than this [m] are dropped
  void validate() const;
};

/// Which rectified view to project into. Right-view pixels are left pixels shifted by -d.
enum class View { kLeft, kRight };

/// Sparse LiDAR disparity in one view.
struct SparseDisparity {
  cv::Mat1f disparity;  ///< [px], 0 = no point (z-buffer: nearest point kept per pixel)
  cv::Mat1s ring;       ///< ring index of the kept point, -1 where empty or unknown
  int points_in_front = 0;  ///< points with min_depth <= z <= max_depth
  int points_in_image = 0;  ///< of those, points that landed inside the image
};

/// Projects `cloud` with the rigid transform `T_cam_lidar` (LiDAR frame -> left optical frame)
/// into `view`, rounding to the nearest pixel; d = fx * B / z. Non-finite points are skipped.
SparseDisparity projectCloud(const LidarCloud& cloud, const Eigen::Isometry3d& T_cam_lidar,
                             const StereoCamera& camera, const ProjectionParams& params,
                             View view = View::kLeft);

/// Recovers rings of a KITTI HDL-64E .bin sweep, stored laser by laser: a new laser starts where
/// the azimuth atan2(y, x) crosses 0 going up. Writes ring 0.. into every point; returns the count.
int recoverRingsBySweepOrder(LidarCloud& cloud);

/// Recovers rings by binning the elevation angle atan2(z, hypot(x, y)) into `num_rings` bins
/// spread between the observed minimum and maximum elevation (for clouds without a ring field and
/// not in sweep order). Ring 0 is the lowest beam. Returns the number of non-empty rings.
int recoverRingsByElevation(LidarCloud& cloud, int num_rings);

/// True when every point has ring >= 0.
bool hasRings(const LidarCloud& cloud);

}  // namespace lidar_stereo_fusion
