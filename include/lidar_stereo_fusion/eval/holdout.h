// Ring hold-out: feed some LiDAR rings to the method and score it on the others. ROS-free.
//
// KITTI has no ground truth for the raw drive in ../shared/data, so accuracy is checked by feeding
// some rings only (the even ones, or every 4th) and using the other rings' points, projected into
// the left image, as the reference depth. The reference shares the LiDAR's own errors and includes
// a few points the camera cannot see (LiDAR-camera parallax); it is a consistency check, not
// KITTI's accumulated ground truth.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {

/// A cloud split by ring index.
struct RingSplit {
  LidarCloud fed;       ///< points of rings with ring % keep_every == 0: the method's input
  LidarCloud held_out;  ///< points of all other rings: the reference
};

/// Splits `cloud`: rings 0, keep_every, 2 keep_every, ... are fed, the others held out
/// (keep_every = 2: even rings in, odd rings out; 4: a 64-ring sweep thinned to 16 rings).
/// Throws std::invalid_argument when a point has no ring (< 0) or keep_every < 2.
RingSplit splitRings(const LidarCloud& cloud, int keep_every);

/// splitRings(cloud, 2): even rings fed, odd rings held out.
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

/// splitRings(cloud, keep_every) + projectReferenceDepth of the held-out rings (default: even rings
/// fed, odd rings as the reference). Throws std::invalid_argument when the reference is empty or
/// keep_every < 2.
HoldoutCase makeRingHoldout(const LidarCloud& cloud, const Eigen::Isometry3d& T_cam_lidar,
                            const StereoCamera& camera, const ProjectionParams& params,
                            int keep_every = 2);

}  // namespace lidar_stereo_fusion
