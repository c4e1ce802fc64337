// KITTI ego-motion on the real drive 0009: every oxts packet reads; the level -> vehicle rotation
// is the receiver's own (its vehicle-frame acceleration and angular rate agree with the turned
// level-frame ones); the devkit poses advance by the velocity; deskewing a real sweep moves the
// rear by about a sweep's travel and the front by the image's offset from the forward instant.
// Missing data fails under CI=true and skips otherwise.
#include <cmath>
#include <iostream>
#include <map>
#include <tuple>

#include <gtest/gtest.h>

#include "data/data_guard.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/kitti_oxts.h"
#include "lidar_stereo_fusion/io/kitti_sweep.h"

namespace lidar_stereo_fusion {
namespace {

const char* const kDrive = "kitti_raw/2011_09_26/2011_09_26_drive_0009_sync";

TEST(KittiOxtsData, LevelFrameQuantitiesTurnIntoTheVehicleFrameOnes) {
  LSF_REQUIRE_DATA(kDrive);
  std::vector<std::string> unstamped;
  const auto samples = kitti::readOxtsDrive(test::dataPath(kDrive), &unstamped);
  ASSERT_EQ(samples.size(), 19u);  // 0, 5, ..., 50 and 16-19, 21-24
  EXPECT_TRUE(unstamped.empty());
  for (const auto& s : samples) {
    SCOPED_TRACE(s.name);
    const kitti::OxtsPacket& p = s.packet;
    const Eigen::Matrix3d vehicle_from_level = kitti::levelFromVehicle(p).transpose();
    // Gravity makes the acceleration a sharp test of roll and pitch (4 deg of roll: 0.7 m/s^2).
    const Eigen::Vector3d a = vehicle_from_level * Eigen::Vector3d(p.af, p.al, p.au);
    EXPECT_NEAR(a.x(), p.ax, 0.03);
    EXPECT_NEAR(a.y(), p.ay, 0.03);
    EXPECT_NEAR(a.z(), p.az, 0.03);
    const kitti::Twist twist = kitti::imuTwist(p);
    EXPECT_NEAR(twist.angular.x(), p.wx, 2e-4);
    EXPECT_NEAR(twist.angular.y(), p.wy, 2e-4);
    EXPECT_NEAR(twist.angular.z(), p.wz, 2e-4);
    EXPECT_NEAR(twist.linear.norm(), std::hypot(p.vf, p.vl, p.vu), 1e-9);
  }
}

TEST(KittiOxtsData, DevkitPosesAdvanceByTheVelocity) {
  LSF_REQUIRE_DATA(kDrive);
  const auto samples = kitti::readOxtsDrive(test::dataPath(kDrive));
  const auto poses = kitti::posesRelativeToFirst(samples);
  ASSERT_EQ(poses.size(), samples.size());
  int checked = 0;
  for (size_t i = 0; i + 1 < samples.size(); ++i) {
    const double dt = samples[i + 1].stamp - samples[i].stamp;
    if (dt > 0.15) continue;  // consecutive packets only (16 .. 19, 21 .. 24)
    SCOPED_TRACE(samples[i].name);
    const Eigen::Isometry3d relative = poses[i].inverse() * poses[i + 1];
    // The mean of the two packets' velocities (in packet i's frame) times the time between them.
    const Eigen::Vector3d expected =
        0.5 * dt *
        (kitti::imuTwist(samples[i].packet).linear +
         relative.linear() * kitti::imuTwist(samples[i + 1].packet).linear);
    // Of a ~1.1 m step: the GPS/INS positions and velocities agree within 3 to 6 cm here; a
    // wrong axis, sign or heading convention is off by metres.
    EXPECT_NEAR((relative.translation() - expected).norm(), 0.0, 0.08)
        << relative.translation().transpose();
    ++checked;
  }
  EXPECT_GE(checked, 6);
}

TEST(KittiOxtsData, DeskewMovesTheRearByASweepsTravelAndTheFrontByTheImageOffset) {
  LSF_REQUIRE_DATA(kDrive);
  const std::string drive = test::dataPath(kDrive);
  const auto stamps = kitti::readDriveStamps(drive);
  const Eigen::Isometry3d T_velo_imu = kitti::readImuToVelo(kitti::calibrationDirOf(drive));
  const LidarCloud raw = kitti::readVelodyneBin(drive + "/velodyne_points/data/0000000020.bin");
  LidarCloud deskewed = raw;
  kitti::deskewFrame(drive, "0000000020", stamps, T_velo_imu, deskewed);
  const double speed =
      kitti::imuTwist(kitti::readOxtsPacket(drive + "/oxts/data/0000000020.txt")).linear.norm();
  const kitti::SweepClock clock = stamps.clockOf(20, "0000000020");
  const double image_after_front = stamps.imageStamp(20, "0000000020") -
                                   (clock.stamp - clock.stamp_after_start + 0.5 * clock.period);
  double front = 0.0, rear = 0.0;
  int n_front = 0, n_rear = 0;
  for (size_t k = 0; k < raw.size(); ++k) {
    const double azimuth = std::atan2(raw[k].y, raw[k].x);
    const double moved = std::hypot(deskewed[k].x - raw[k].x, deskewed[k].y - raw[k].y);
    if (std::abs(azimuth) < 0.05) front += moved, ++n_front;
    if (std::abs(azimuth) > M_PI - 0.05) rear += moved, ++n_rear;
  }
  ASSERT_GT(n_front, 100);
  ASSERT_GT(n_rear, 100);
  EXPECT_GT(speed, 9.0);
  EXPECT_NEAR(front / n_front, speed * std::abs(image_after_front), 0.02);
  EXPECT_NEAR(rear / n_rear, speed * 0.5 * clock.period, 0.06);
}

/// Mean distance [m] from the points of `a` above the ground (z > -1.3 m), 3 to 30 m away and
/// within 60 deg of the front, to their nearest point of `b`, counting those nearer than 0.5 m.
double meanNearestDistance(const LidarCloud& a, const LidarCloud& b) {
  constexpr double kCell = 0.5;
  auto key = [](double x, double y, double z) {
    return std::make_tuple(static_cast<int>(std::floor(x / kCell)),
                           static_cast<int>(std::floor(y / kCell)),
                           static_cast<int>(std::floor(z / kCell)));
  };
  std::map<std::tuple<int, int, int>, std::vector<Eigen::Vector3d>> grid;
  for (const LidarPoint& p : b) {
    if (p.z > -1.3f) grid[key(p.x, p.y, p.z)].emplace_back(p.x, p.y, p.z);
  }
  double sum = 0.0;
  int n = 0;
  for (const LidarPoint& p : a) {
    const double range = std::hypot(p.x, p.y);
    if (p.z <= -1.3f || range < 3.0 || range > 30.0 || std::abs(std::atan2(p.y, p.x)) > M_PI / 3) {
      continue;
    }
    const Eigen::Vector3d q(p.x, p.y, p.z);
    const auto [i, j, k] = key(p.x, p.y, p.z);
    double best = kCell;
    for (int di = -1; di <= 1; ++di) {
      for (int dj = -1; dj <= 1; ++dj) {
        for (int dk = -1; dk <= 1; ++dk) {
          const auto cell = grid.find({i + di, j + dj, k + dk});
          if (cell == grid.end()) continue;
          for (const Eigen::Vector3d& r : cell->second) best = std::min(best, (r - q).norm());
        }
      }
    }
    if (best < kCell) sum += best, ++n;
  }
  return n > 0 ? sum / n : NAN;
}

LidarCloud transformed(const LidarCloud& cloud, const Eigen::Isometry3d& T) {
  LidarCloud out = cloud;
  for (LidarPoint& p : out) {
    const Eigen::Vector3d q = T * Eigen::Vector3d(p.x, p.y, p.z);
    p.x = static_cast<float>(q.x()), p.y = static_cast<float>(q.y()),
    p.z = static_cast<float>(q.z());
  }
  return out;
}

// The consecutive sweeps 15 .. 25 (1 m apart), each put into the next one's frame with the oxts
// poses: deskewed to their oxts instants they overlap better than as measured, in all 10 pairs.
TEST(KittiOxtsData, DeskewedConsecutiveSweepsAgreeBetter) {
  LSF_REQUIRE_DATA(kDrive);
  const std::string drive = test::dataPath(kDrive);
  const auto stamps = kitti::readDriveStamps(drive);
  const Eigen::Isometry3d T_velo_imu = kitti::readImuToVelo(kitti::calibrationDirOf(drive));
  const auto samples = kitti::readOxtsDrive(drive);
  const auto poses = kitti::posesRelativeToFirst(samples);
  std::map<size_t, size_t> by_frame;  // frame number -> sample
  for (size_t s = 0; s < samples.size(); ++s) by_frame[kitti::frameIndex(samples[s].name)] = s;
  auto sweep = [&](size_t frame, bool deskew) {
    const std::string name = samples[by_frame.at(frame)].name;
    LidarCloud cloud = kitti::readVelodyneBin(drive + "/velodyne_points/data/" + name + ".bin");
    if (deskew) {
      const kitti::OxtsSample& s = samples[by_frame.at(frame)];
      kitti::deskewSweep(cloud, stamps.clockOf(frame, name),
                         kitti::transformTwist(kitti::imuTwist(s.packet), T_velo_imu), s.stamp);
    }
    return cloud;
  };
  double raw_sum = 0.0, deskewed_sum = 0.0;
  int better = 0, pairs = 0;
  for (size_t frame = 15; frame < 25; ++frame) {
    const Eigen::Isometry3d next_from_this = T_velo_imu * poses[by_frame.at(frame + 1)].inverse() *
                                             poses[by_frame.at(frame)] * T_velo_imu.inverse();
    const double raw = meanNearestDistance(transformed(sweep(frame, false), next_from_this),
                                           sweep(frame + 1, false));
    const double deskewed = meanNearestDistance(transformed(sweep(frame, true), next_from_this),
                                                sweep(frame + 1, true));
    raw_sum += raw, deskewed_sum += deskewed, ++pairs;
    if (deskewed < raw) ++better;
  }
  std::cout << "mean nearest-point distance of consecutive sweeps (front 120 deg, above ground): "
            << raw_sum / pairs << " m as measured, " << deskewed_sum / pairs << " m deskewed\n";
  EXPECT_EQ(better, pairs);
  EXPECT_LT(deskewed_sum, 0.98 * raw_sum);
}

}  // namespace
}  // namespace lidar_stereo_fusion
