// When each point of a KITTI raw sweep was measured, and untwisting ("deskewing") a sweep with the
// OXTS velocities. ROS-free; the motion itself is core/motion_compensation.h's.
//
// The HDL-64E spins clockwise seen from above; a KITTI sweep runs from the rear
// (velodyne_points/timestamps_start.txt) through the front (timestamps.txt, when the cameras are
// triggered) to the rear again (timestamps_end.txt). A point's time is linear in its azimuth
// atan2(y, x) [rad, Velodyne frame]: since the start = (pi - azimuth) / (2 pi) * period.
#pragma once

#include <string>
#include <vector>

#include "lidar_stereo_fusion/core/types.h"
#include "lidar_stereo_fusion/io/kitti_oxts.h"

namespace lidar_stereo_fusion {
namespace kitti {

/// The clock of one sweep.
struct SweepClock {
  double stamp = 0.0;              ///< [s] since the epoch: the cloud's stamp
  double period = 0.1;             ///< [s] from the sweep's start to its end
  double stamp_after_start = 0.1;  ///< [s] from the sweep's start to `stamp`
};

/// The clock of a sweep stamped at `stamp` [s]: at its end (stamp_is_end, from
/// timestamps_end.txt) or at its forward-facing instant (timestamps.txt). The period is
/// stamp - start when stamp is the end and `start` (timestamps_start.txt, NaN if unknown) gives a
/// period in (0, 1) s, else 0.1 s (the HDL-64E at 10 Hz). kitti_to_bag and kitti_runner --deskew
/// both use this rule.
SweepClock sweepClock(double stamp, double start, bool stamp_is_end);

/// Time [s] relative to the clock's stamp of a point at (x, y) [m, Velodyne frame]:
/// (pi - atan2(y, x)) / (2 pi) * period - stamp_after_start; in [-stamp_after_start,
/// period - stamp_after_start] (a point at the origin counts as azimuth 0).
double azimuthTime(double x, double y, const SweepClock& clock);

/// Sets every point's `time` by azimuthTime (non-finite points get 0).
void setPointTimesFromAzimuth(LidarCloud& cloud, const SweepClock& clock);

/// The stamps of a drive's frames, indexed by frame number; NaN where a file has a blank line
/// (a dropped sample) or no line.
struct DriveStamps {
  std::vector<double> image;        ///< image_02/timestamps.txt
  std::vector<double> sweep;        ///< the sweeps' stamps: timestamps_end.txt, else timestamps.txt
  std::vector<double> sweep_start;  ///< timestamps_start.txt (empty when absent)
  bool sweep_is_end = true;         ///< `sweep` holds the sweeps' ends

  /// The clock of frame `index`'s sweep; throws std::runtime_error naming `name` and the missing
  /// stamp (image or sweep) when either is NaN or beyond its file.
  SweepClock clockOf(size_t index, const std::string& name) const;
  /// image_02 stamp of frame `index` [s]; throws like clockOf.
  double imageStamp(size_t index, const std::string& name) const;
};

/// Reads image_02/timestamps.txt and velodyne_points/timestamps{_end,,_start}.txt of `drive_dir`.
/// Throws std::runtime_error naming a missing or malformed file.
DriveStamps readDriveStamps(const std::string& drive_dir);

/// Untwists a KITTI sweep: sets the point times by azimuth (setPointTimesFromAzimuth), then moves
/// every point to the instant `target_stamp` [s since the epoch] (the left image's) under the
/// constant twist `velodyne_twist` (Velodyne frame) with core/motion_compensation's
/// constantVelocityMotion, sampled at `samples` instants over the sweep. Throws
/// std::invalid_argument for non-finite inputs or samples < 1.
void deskewSweep(LidarCloud& cloud, const SweepClock& clock, const Twist& velodyne_twist,
                 double target_stamp, int samples = 5);

/// Deskews the sweep of frame `name` of `drive_dir` by deskewSweep: the twist of its packet
/// oxts/data/<name>.txt (imuTwist) turned into the Velodyne frame with `T_velo_imu`
/// (calib_imu_to_velo.txt), its clock from `stamps`, the target its image_02 stamp. Throws
/// std::runtime_error naming the frame and what is missing or malformed (packet, stamps); the
/// cloud is unchanged then.
void deskewFrame(const std::string& drive_dir, const std::string& name, const DriveStamps& stamps,
                 const Eigen::Isometry3d& T_velo_imu, LidarCloud& cloud);

}  // namespace kitti
}  // namespace lidar_stereo_fusion
