// Per-point time of a KITTI raw sweep from its azimuth, the drive's stamps, and deskewing.
#include "lidar_stereo_fusion/io/kitti_sweep.h"

#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include "lidar_stereo_fusion/core/motion_compensation.h"
#include "lidar_stereo_fusion/io/kitti.h"

namespace lidar_stereo_fusion {
namespace kitti {
namespace {

namespace fs = std::filesystem;

constexpr double kDefaultSweepPeriod = 0.1;  ///< [s] HDL-64E at 10 Hz
constexpr double kMaxSweepPeriod = 1.0;      ///< [s] a longer start-to-end span is not one sweep

double stampAt(const std::vector<double>& stamps, size_t index) {
  return index < stamps.size() ? stamps[index] : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

SweepClock sweepClock(double stamp, double start, bool stamp_is_end) {
  SweepClock clock;
  clock.stamp = stamp;
  clock.period = kDefaultSweepPeriod;
  if (stamp_is_end && std::isfinite(start) && stamp > start && stamp - start < kMaxSweepPeriod) {
    clock.period = stamp - start;
  }
  clock.stamp_after_start = stamp_is_end ? clock.period : 0.5 * clock.period;
  return clock;
}

double azimuthTime(double x, double y, const SweepClock& clock) {
  const double azimuth = std::atan2(y, x);  // 0 at the origin
  // Clockwise from the rear (azimuth +pi) at the sweep start to the rear again (-pi) at its end.
  const double since_start = (M_PI - azimuth) / (2.0 * M_PI) * clock.period;
  return since_start - clock.stamp_after_start;
}

void setPointTimesFromAzimuth(LidarCloud& cloud, const SweepClock& clock) {
  for (LidarPoint& p : cloud) {
    const bool finite = std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
    p.time = finite ? static_cast<float>(azimuthTime(p.x, p.y, clock)) : 0.f;
  }
}

SweepClock DriveStamps::clockOf(size_t index, const std::string& name) const {
  const double stamp = stampAt(sweep, index);
  if (!std::isfinite(stamp)) {
    throw std::runtime_error("frame " + name + " has no Velodyne timestamp (" +
                             (sweep_is_end ? "timestamps_end.txt" : "timestamps.txt") + " line " +
                             std::to_string(index + 1) + " is blank or missing)");
  }
  return sweepClock(stamp, stampAt(sweep_start, index), sweep_is_end);
}

double DriveStamps::imageStamp(size_t index, const std::string& name) const {
  const double stamp = stampAt(image, index);
  if (!std::isfinite(stamp)) {
    throw std::runtime_error("frame " + name + " has no image_02 timestamp (line " +
                             std::to_string(index + 1) + " is blank or missing)");
  }
  return stamp;
}

DriveStamps readDriveStamps(const std::string& drive_dir) {
  const fs::path drive(drive_dir);
  const fs::path velo = drive / "velodyne_points";
  auto require = [](const fs::path& path) {
    if (!fs::is_regular_file(path)) throw std::runtime_error("KITTI: missing " + path.string());
    return path.string();
  };
  DriveStamps stamps;
  stamps.image = readTimestamps(require(drive / "image_02" / "timestamps.txt"));
  stamps.sweep_is_end = fs::is_regular_file(velo / "timestamps_end.txt");
  stamps.sweep = readTimestamps(
      require(velo / (stamps.sweep_is_end ? "timestamps_end.txt" : "timestamps.txt")));
  if (fs::is_regular_file(velo / "timestamps_start.txt")) {
    stamps.sweep_start = readTimestamps((velo / "timestamps_start.txt").string());
  }
  return stamps;
}

void deskewSweep(LidarCloud& cloud, const SweepClock& clock, const Twist& velodyne_twist,
                 double target_stamp, int samples) {
  if (!velodyne_twist.linear.allFinite() || !velodyne_twist.angular.allFinite() ||
      !std::isfinite(target_stamp) || !std::isfinite(clock.stamp) || !std::isfinite(clock.period) ||
      !std::isfinite(clock.stamp_after_start)) {
    throw std::invalid_argument("deskewSweep: a velocity, stamp or period is not finite");
  }
  setPointTimesFromAzimuth(cloud, clock);
  const auto [first, last] = timeSpan(cloud);
  // Constant velocity: translation is linear and rotation keeps its axis in time, so the
  // interpolation between any two samples is exact; a few samples cost nothing.
  const SweepMotion motion =
      constantVelocityMotion(velodyne_twist.linear, velodyne_twist.angular,
                             target_stamp - clock.stamp, sampleTimes(first, last, samples));
  compensateMotion(cloud, motion);
}

void deskewFrame(const std::string& drive_dir, const std::string& name, const DriveStamps& stamps,
                 const Eigen::Isometry3d& T_velo_imu, LidarCloud& cloud) {
  const fs::path packet_path = fs::path(drive_dir) / "oxts" / "data" / (name + ".txt");
  if (!fs::is_regular_file(packet_path)) {
    throw std::runtime_error("frame " + name + " has no oxts packet " + packet_path.string());
  }
  const size_t index = frameIndex(name);
  const SweepClock clock = stamps.clockOf(index, name);
  const double target = stamps.imageStamp(index, name);
  const Twist twist = transformTwist(imuTwist(readOxtsPacket(packet_path.string())), T_velo_imu);
  deskewSweep(cloud, clock, twist, target);
}

}  // namespace kitti
}  // namespace lidar_stereo_fusion
