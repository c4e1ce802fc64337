// Stage 1: projection of a LiDAR sweep into a rectified view as sparse disparity (paper Eq. 1-2),
// and recovery of scan-line (ring) indices for clouds that carry none.
#pragma once

#include <string>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

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

/// Recovers rings of a KITTI HDL-64E .bin sweep, stored laser by laser: a new laser starts where
/// the azimuth atan2(y, x) crosses 0 going up (counted only after the current laser has passed the
/// +-180 deg wrap, so azimuth jitter around 0 cannot split a laser). Writes ring 0.. into every
/// point in storage order (on KITTI ring 0 is the highest beam); non-finite points get the ring of
/// the points around them. Returns the number of rings (0 for an empty cloud).
int recoverRingsBySweepOrder(LidarCloud& cloud);

/// Recovers rings from the elevation angle atan2(z, hypot(x, y)) for clouds without a ring field
/// and not in sweep order, from sensors whose beams share one origin (VLS-128, Ouster, ...): the
/// sorted elevations are split into beams at the (at most num_rings - 1) widest gaps that are at
/// least `min_gap_deg` [deg] wide. Unlike uniform bins this follows non-uniform beam spacing
/// (VLS-128: 0.11 deg in the centre, several degrees at the edges) and does not invent beams that
/// returned nothing. Ring 0 is the lowest beam; non-finite points get -1. Returns the number of
/// rings found (<= num_rings). Throws std::invalid_argument for num_rings < 1 or min_gap_deg < 0.
int recoverRingsByElevation(LidarCloud& cloud, int num_rings, double min_gap_deg = 0.05);

/// True when every point has ring >= 0.
bool hasRings(const LidarCloud& cloud);

/// Where the rings of a sweep came from.
enum class RingSource {
  kField,       ///< the sensor's ring field, plausible as it was
  kSweepOrder,  ///< recoverRingsBySweepOrder (KITTI .bin / kitti2bag order)
  kElevation,   ///< recoverRingsByElevation
};
/// "ring_field", "sweep_order" or "elevation".
std::string ringSourceName(RingSource source);

/// Outcome of ensureRings(): the method used, the rings it found, and why earlier methods were
/// passed over (empty when the first one was plausible).
struct RingRecovery {
  RingSource source = RingSource::kField;
  int rings = 0;          ///< distinct scan lines (max ring + 1)
  bool plausible = true;  ///< false: even the last fallback failed the checks (used anyway)
  std::string fallbacks;  ///< e.g. "ring field: 1 ring for 120000 points; sweep order: ..."
};

/// Empty when the rings of `cloud` look like a real scan pattern, else what is wrong: fewer than
/// 2 rings for >= 100 points, more than `max_rings`, more than a quarter of the rings with fewer
/// than 5 points, or mean elevations per ring that are not (at least 80 % of neighbouring pairs)
/// monotonic in the ring index. Points with ring < 0 are ignored.
std::string ringPlausibilityProblem(const LidarCloud& cloud, int max_rings);

/// Makes sure every point has a plausible ring, trying in order: the ring field (when
/// `has_ring_field` and plausible), the sweep order rule of the offline path, and elevation
/// binning into at most `num_rings` beams (num_rings is also the most rings accepted from the
/// other two, times 2: a sensor with more beams than configured is still recognised). Every
/// recovery is checked with ringPlausibilityProblem(); the result says which method was used and
/// why the others were not. Throws std::invalid_argument for num_rings < 1.
RingRecovery ensureRings(LidarCloud& cloud, bool has_ring_field, int num_rings);

}  // namespace lidar_stereo_fusion
