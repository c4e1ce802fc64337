// The sweep as the KITTI protocols feed it: as recorded (rings from the sweep order, as
// kitti::loadFrame recovers them), or with its order lost, as a cloud arrives from a
// depth-completion dataset, after a VoxelGrid or from a merge of LiDARs. Then the rings are
// forgotten and recovered as the node recovers them for a cloud without a ring field
// (ensureRings). `accuracy_report --sweep-order`. ROS-free.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "lidar_stereo_fusion/core/ring_recovery.h"
#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {

enum class SweepOrder {
  kRecorded,          ///< as recorded: the rings the sweep order gives
  kShuffled,          ///< every point, in random order
  kImageRows,         ///< the points in the left image by image row, then the others
  kImageRowsCropped,  ///< only the points in the left image, by image row (a depth-completion set)
};

/// "recorded", "shuffled", "image-rows", "image-rows-cropped", in the enum's order.
std::vector<std::string> sweepOrderNames();
std::string sweepOrderName(SweepOrder order);
/// Throws std::invalid_argument naming the valid names for any other.
SweepOrder parseSweepOrder(const std::string& name);

/// A permutation of 0 .. n-1: std::shuffle of the identity with std::mt19937(seed).
std::vector<std::size_t> shuffledIndices(std::size_t n, unsigned seed);

/// Image-row order: the indices of the points that land in the left image (depth >= 0.5 m,
/// column and row rounded as projectCloud rounds them) sorted by row, then column, then index;
/// then, unless `crop`, the indices of the other points in storage order. Throws
/// std::invalid_argument for an invalid camera.
std::vector<std::size_t> imageRowIndices(const LidarCloud& cloud,
                                         const Eigen::Isometry3d& T_cam_lidar,
                                         const StereoCamera& camera, bool crop);

/// A sweep in another order, with its rings recovered.
struct ReorderedSweep {
  LidarCloud cloud;
  RingRecovery rings;  ///< kRecorded: source kField and the rings the cloud has
};

/// `cloud` in `order` (kShuffled with `seed`), every ring set to -1 and then recovered by
/// ensureRings(cloud, false, num_rings), as the node does for a cloud without a ring field.
/// kRecorded returns the cloud unchanged. Throws std::invalid_argument for num_rings < 1, and for
/// an invalid camera with the image-row orders.
ReorderedSweep reorderSweep(const LidarCloud& cloud, SweepOrder order,
                            const Eigen::Isometry3d& T_cam_lidar, const StereoCamera& camera,
                            int num_rings, unsigned seed);

}  // namespace lidar_stereo_fusion
