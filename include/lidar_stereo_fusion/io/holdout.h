// Ring hold-out: feed some LiDAR rings to the method and score it on the others. ROS-free.
//
// KITTI has no ground truth for the raw drive in ../shared/data, so accuracy is checked by feeding
// the even rings only and using the odd rings' points, projected into the left image, as the
// reference depth. The reference shares the LiDAR's own errors and includes a few points the camera
// cannot see (LiDAR-camera parallax); it is a consistency check, not KITTI's accumulated ground
// truth.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {

/// A cloud split by ring parity.
struct RingSplit {
  LidarCloud fed;       ///< points of even rings (0, 2, ...): the method's input
  LidarCloud held_out;  ///< points of odd rings (1, 3, ...): the reference
};

/// Splits `cloud` by ring parity. Throws std::invalid_argument when a point has no ring (< 0).
RingSplit splitRingsEvenOdd(const LidarCloud& cloud);

/// Reference depth [m] of the held-out points in the left image: every finite point with
/// params.min_depth <= z <= params.max_depth is projected (u = fx X/z + cx, v = fy Y/z + cy,
/// rounded to the nearest pixel as projectCloud does), the nearest point wins a pixel (z-buffer),
/// and the pixel stores its z. 0 = no reference. Throws std::invalid_argument on an invalid camera.
cv::Mat1f projectReferenceDepth(const LidarCloud& held_out, const Eigen::Isometry3d& T_cam_lidar,
                                const StereoCamera& camera, const ProjectionParams& params);

/// One hold-out case: the cloud to feed and the reference depth to score against.
struct HoldoutCase {
  LidarCloud fed;
  cv::Mat1f reference_depth;  ///< [m], 0 = no value
};

/// splitRingsEvenOdd + projectReferenceDepth of the odd rings. Throws when the reference is empty.
HoldoutCase makeRingHoldout(const LidarCloud& cloud, const Eigen::Isometry3d& T_cam_lidar,
                            const StereoCamera& camera, const ProjectionParams& params);

}  // namespace lidar_stereo_fusion
