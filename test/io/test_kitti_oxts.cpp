// KITTI ego-motion inputs, exact: the OXTS packet reader and its errors, calib_imu_to_velo.txt,
// the IMU's twist from the level-frame velocities and its transfer to the Velodyne, the devkit's
// Mercator poses, the azimuth time rule and the sweep clock, and deskewing a sweep taken by a
// moving sensor back to the static scene. Files are written at test time into a temp folder.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/io/kitti_oxts.h"
#include "lidar_stereo_fusion/io/kitti_sweep.h"

namespace lidar_stereo_fusion {
namespace {

namespace fs = std::filesystem;
using kitti::OxtsPacket;

/// A fresh temp folder per test, removed at the end.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            ("lsf_oxts_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  /// Writes `text` into <dir>/<name> (folders created); returns the path.
  std::string write(const std::string& name, const std::string& text) const {
    fs::create_directories((path_ / name).parent_path());
    std::ofstream(path_ / name) << text;
    return (path_ / name).string();
  }
  std::string path() const { return path_.string(); }

 private:
  fs::path path_;
};

// Frame 0000000000 of drive 2011_09_26_0009 with round numbers in the checked places.
const char kPacket[] =
    "49.5 8.25 114.5 0.072 0.0015 -0.27 -2.93 10.28 10.5 0.125 -0.075 0.006 0.845 9.91 0.042 "
    "0.136 9.95 0.0166 -0.0368 0.0033 0.0167 -0.037 0.0006 0.43 0.058 4 7 4 4 0\n";

/// One value of an OXTS packet: its dataformat.txt name, its member and its value in kPacket.
template <class T>
struct PacketValue {
  const char* name;
  T OxtsPacket::*member;
  T value;
};

TEST(KittiOxts, ReadsThe30ValuesOfAPacket) {
  TempDir dir;
  const OxtsPacket p = kitti::readOxtsPacket(dir.write("0000000000.txt", kPacket));
  const PacketValue<double> reals[] = {{"lat", &OxtsPacket::lat, 49.5},
                                       {"lon", &OxtsPacket::lon, 8.25},
                                       {"alt", &OxtsPacket::alt, 114.5},
                                       {"roll", &OxtsPacket::roll, 0.072},
                                       {"pitch", &OxtsPacket::pitch, 0.0015},
                                       {"yaw", &OxtsPacket::yaw, -0.27},
                                       {"vn", &OxtsPacket::vn, -2.93},
                                       {"ve", &OxtsPacket::ve, 10.28},
                                       {"vf", &OxtsPacket::vf, 10.5},
                                       {"vl", &OxtsPacket::vl, 0.125},
                                       {"vu", &OxtsPacket::vu, -0.075},
                                       {"ax", &OxtsPacket::ax, 0.006},
                                       {"ay", &OxtsPacket::ay, 0.845},
                                       {"az", &OxtsPacket::az, 9.91},
                                       {"af", &OxtsPacket::af, 0.042},
                                       {"al", &OxtsPacket::al, 0.136},
                                       {"au", &OxtsPacket::au, 9.95},
                                       {"wx", &OxtsPacket::wx, 0.0166},
                                       {"wy", &OxtsPacket::wy, -0.0368},
                                       {"wz", &OxtsPacket::wz, 0.0033},
                                       {"wf", &OxtsPacket::wf, 0.0167},
                                       {"wl", &OxtsPacket::wl, -0.037},
                                       {"wu", &OxtsPacket::wu, 0.0006},
                                       {"pos_accuracy", &OxtsPacket::pos_accuracy, 0.43},
                                       {"vel_accuracy", &OxtsPacket::vel_accuracy, 0.058}};
  for (const auto& v : reals) EXPECT_EQ(p.*v.member, v.value) << v.name;
  const PacketValue<int> integers[] = {{"navstat", &OxtsPacket::navstat, 4},
                                       {"numsats", &OxtsPacket::numsats, 7},
                                       {"posmode", &OxtsPacket::posmode, 4},
                                       {"velmode", &OxtsPacket::velmode, 4},
                                       {"orimode", &OxtsPacket::orimode, 0}};
  for (const auto& v : integers) EXPECT_EQ(p.*v.member, v.value) << v.name;
  // Blank lines around the packet and no final newline are fine.
  const std::string text(kPacket);
  EXPECT_EQ(kitti::readOxtsPacket(dir.write("b.txt", "\n" + text.substr(0, text.size() - 1))).vf,
            10.5);
}

/// Reading `text` fails with every one of `parts` in the message.
void expectPacketError(const TempDir& dir, const std::string& text,
                       const std::vector<std::string>& parts) {
  const std::string path = dir.write("bad.txt", text);
  try {
    kitti::readOxtsPacket(path);
    ADD_FAILURE() << "accepted: " << text;
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    for (const std::string& part : parts) EXPECT_NE(what.find(part), std::string::npos) << what;
  }
}

TEST(KittiOxts, MalformedPacketsAreNamedByFileLineAndValue) {
  TempDir dir;
  const std::string text(kPacket);
  /// kPacket with `from` replaced by `to`.
  const auto edited = [&text](const std::string& from, const std::string& to) {
    return std::string(text).replace(text.find(from), from.size(), to);
  };
  // The file's text, and what the error must say besides the file's path.
  const struct {
    std::string text;
    std::vector<std::string> said;
  } cases[] = {
      {"", {"no packet line"}},
      {"1 2 3\n", {"line 1", "has 3 values, expected 30"}},
      {"\n" + text + text, {"line 3", "a second packet"}},
      {edited("10.5", "10,5"), {"line 1", "value 9 (vf)", "'10,5'"}},
      {edited("-0.27", "nan"), {"value 6 (yaw)", "not a finite number"}},
      {edited(" 7 4 4 0", " 7.5 4 4 0"), {"value 27 (numsats)", "not an integer"}},
  };
  for (const auto& c : cases) expectPacketError(dir, c.text, c.said);
  EXPECT_THROW(kitti::readOxtsPacket(dir.path() + "/none.txt"), std::runtime_error);
}

TEST(KittiOxts, ReadsImuToVeloAndRejectsABadOne) {
  TempDir dir;
  dir.write("calib_imu_to_velo.txt",
            "calib_time: 25-May-2012 16:47:16\nR: 0 -1 0 1 0 0 0 0 1\nT: -0.8 0.3 -0.8\n");
  const Eigen::Isometry3d T = kitti::readImuToVelo(dir.path());
  // Maps IMU coordinates into Velodyne coordinates: IMU x (forward) -> Velodyne +y.
  EXPECT_TRUE((T.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-15));
  EXPECT_EQ(T.translation(), Eigen::Vector3d(-0.8, 0.3, -0.8));
  dir.write("calib_imu_to_velo.txt", "R: 2 0 0 0 1 0 0 0 1\nT: 0 0 0\n");
  try {
    kitti::readImuToVelo(dir.path());
    ADD_FAILURE() << "accepted a scaled R";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("calib_imu_to_velo.txt key 'R'"), std::string::npos);
  }
  dir.write("calib_imu_to_velo.txt", "R: 1 0 0 0 1 0 0 0 1\n");
  EXPECT_THROW(kitti::readImuToVelo(dir.path()), std::runtime_error);  // no T
  fs::remove(dir.path() + "/calib_imu_to_velo.txt");
  EXPECT_THROW(kitti::readImuToVelo(dir.path()), std::runtime_error);
}

TEST(KittiOxts, ImuTwistTurnsTheLevelFrameIntoTheVehicleFrame) {
  OxtsPacket p;
  p.vf = 10.0, p.vl = 0.5, p.vu = -0.25;
  p.wf = 0.01, p.wl = 0.02, p.wu = 0.3;
  kitti::Twist level = kitti::imuTwist(p);  // level road: as they are
  EXPECT_EQ(level.linear, Eigen::Vector3d(10.0, 0.5, -0.25));
  EXPECT_EQ(level.angular, Eigen::Vector3d(0.01, 0.02, 0.3));
  // Rolled 90 deg left side up: the vehicle's y axis points up, its z axis right (-left).
  p.roll = M_PI / 2;
  const kitti::Twist rolled = kitti::imuTwist(p);
  EXPECT_TRUE(rolled.linear.isApprox(Eigen::Vector3d(10.0, -0.25, -0.5), 1e-12));
  EXPECT_TRUE(rolled.angular.isApprox(Eigen::Vector3d(0.01, 0.3, -0.02), 1e-12));
  // Pitched 90 deg front down: the vehicle's x axis points down, its z axis forward.
  p.roll = 0.0, p.pitch = M_PI / 2;
  const kitti::Twist pitched = kitti::imuTwist(p);
  EXPECT_TRUE(pitched.linear.isApprox(Eigen::Vector3d(0.25, 0.5, 10.0), 1e-12));
}

TEST(KittiOxts, TwistMovesToTheVelodyneThroughTheCalibration) {
  // Velodyne turned 90 deg about z (its x = IMU y) and 2 m ahead of the IMU.
  Eigen::Isometry3d T_imu_velo = Eigen::Isometry3d::Identity();
  T_imu_velo.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_imu_velo.translation() = Eigen::Vector3d(2.0, 0.0, 0.0);
  kitti::Twist imu;
  imu.linear = Eigen::Vector3d(10.0, 0.0, 0.0);
  imu.angular = Eigen::Vector3d(0.0, 0.0, 0.5);  // turning left
  const kitti::Twist velo = kitti::transformTwist(imu, T_imu_velo.inverse());
  // 2 m ahead of the turning IMU moves left at 0.5 * 2 = 1 m/s besides 10 m/s forward; in the
  // Velodyne frame forward is -y and left is +x.
  EXPECT_TRUE(velo.linear.isApprox(Eigen::Vector3d(1.0, -10.0, 0.0), 1e-12)) << velo.linear;
  EXPECT_TRUE(velo.angular.isApprox(Eigen::Vector3d(0.0, 0.0, 0.5), 1e-12)) << velo.angular;
  // Without rotation the frames only differ by the lever arm.
  const kitti::Twist still = kitti::transformTwist(kitti::Twist{}, T_imu_velo.inverse());
  EXPECT_EQ(still.linear, Eigen::Vector3d::Zero());
}

TEST(KittiOxts, MercatorPosesFollowTheDevkit) {
  OxtsPacket a;
  a.lat = 49.0, a.lon = 8.4, a.alt = 110.0, a.yaw = 0.5;
  const double scale = kitti::mercatorScale(a.lat);
  EXPECT_DOUBLE_EQ(scale, std::cos(49.0 * M_PI / 180.0));
  OxtsPacket b = a;
  b.lon += 1e-4;  // east by scale * 1e-4 * pi * r / 180
  b.alt += 2.0;
  b.yaw += 0.1;
  const Eigen::Isometry3d pose_a = kitti::mercatorPose(a, scale);
  EXPECT_NEAR(pose_a.translation().x(), scale * 8.4 * M_PI * 6378137.0 / 180.0, 1e-6);
  EXPECT_NEAR(pose_a.translation().y(),
              scale * 6378137.0 * std::log(std::tan((90.0 + 49.0) * M_PI / 360.0)), 1e-6);
  const auto poses = kitti::posesRelativeToFirst({{"0", 0.0, a}, {"1", 0.1, b}});
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_TRUE(poses[0].isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  // In the first IMU frame (heading 0.5 rad from east): east is (cos 0.5, -sin 0.5).
  const double east = scale * 1e-4 * M_PI * 6378137.0 / 180.0;
  EXPECT_NEAR(poses[1].translation().x(), east * std::cos(0.5), 1e-6);
  EXPECT_NEAR(poses[1].translation().y(), -east * std::sin(0.5), 1e-6);
  EXPECT_NEAR(poses[1].translation().z(), 2.0, 1e-9);
  EXPECT_NEAR(Eigen::AngleAxisd(poses[1].linear()).angle(), 0.1, 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(poses[1].linear()).axis().z(), 1.0, 1e-12);
}

TEST(KittiOxts, DriveReaderPairsPacketsWithTheirStampsAndNamesUnstampedOnes) {
  TempDir dir;
  for (const char* name : {"0000000000", "0000000002", "0000000003"}) {
    dir.write(std::string("oxts/data/") + name + ".txt", kPacket);
  }
  dir.write("oxts/timestamps.txt",
            "2011-09-26 13:08:24.5\n2011-09-26 13:08:24.6\n2011-09-26 13:08:24.7\n\n");
  std::vector<std::string> unstamped;
  const auto samples = kitti::readOxtsDrive(dir.path(), &unstamped);
  ASSERT_EQ(samples.size(), 2u);
  EXPECT_EQ(samples[0].name, "0000000000");
  EXPECT_EQ(samples[1].name, "0000000002");
  EXPECT_NEAR(samples[1].stamp - samples[0].stamp, 0.2, 1e-6);
  EXPECT_EQ(samples[1].packet.vf, 10.5);
  EXPECT_EQ(unstamped, std::vector<std::string>{"0000000003"});  // blank line 4
  dir.write("oxts/data/x.txt", kPacket);
  EXPECT_THROW(kitti::readOxtsDrive(dir.path()), std::runtime_error);  // not a frame number
  EXPECT_THROW(kitti::readOxtsDrive(dir.path() + "/none"), std::runtime_error);
}

TEST(KittiSweep, AzimuthTimeRunsClockwiseFromTheRear) {
  const kitti::SweepClock clock = kitti::sweepClock(100.1, 100.0, true);  // stamped at the end
  EXPECT_NEAR(clock.period, 0.1, 1e-12);
  EXPECT_NEAR(clock.stamp_after_start, 0.1, 1e-12);
  const double period = clock.period;
  EXPECT_NEAR(kitti::azimuthTime(-1.0, 1e-300, clock), -period, 1e-12);      // rear, start
  EXPECT_NEAR(kitti::azimuthTime(0.0, 1.0, clock), -0.75 * period, 1e-12);   // left
  EXPECT_NEAR(kitti::azimuthTime(1.0, 0.0, clock), -0.5 * period, 1e-12);    // front
  EXPECT_NEAR(kitti::azimuthTime(0.0, -1.0, clock), -0.25 * period, 1e-12);  // right
  EXPECT_NEAR(kitti::azimuthTime(-1.0, -1e-300, clock), 0.0, 1e-12);         // rear, end
  // Stamped at the forward instant (no timestamps_end.txt): front = 0, 0.1 s sweep.
  const kitti::SweepClock forward = kitti::sweepClock(100.05, NAN, false);
  EXPECT_EQ(forward.period, 0.1);
  EXPECT_EQ(forward.stamp_after_start, 0.05);
  EXPECT_EQ(kitti::azimuthTime(1.0, 0.0, forward), 0.0);
  // No start, or an implausible one: 0.1 s.
  EXPECT_EQ(kitti::sweepClock(100.1, NAN, true).period, 0.1);
  EXPECT_EQ(kitti::sweepClock(100.1, 98.0, true).period, 0.1);
  EXPECT_EQ(kitti::sweepClock(100.1, 100.2, true).period, 0.1);
  LidarCloud cloud(2);
  cloud[0].x = 1.f;
  cloud[1].x = NAN;
  kitti::setPointTimesFromAzimuth(cloud, clock);
  EXPECT_FLOAT_EQ(cloud[0].time, static_cast<float>(-0.5 * period));
  EXPECT_EQ(cloud[1].time, 0.f);
}

TEST(KittiSweep, DeskewingASweepOfAMovingSensorRestoresTheScene) {
  // A sensor moving at 10 m/s forward while turning at 0.5 rad/s; the scene (in the sensor frame
  // at the target instant, 0.02 s after the forward instant) is a ring of posts 8 m away. Each
  // measurement is where a post was seen from the sensor at the time its azimuth gives.
  kitti::Twist twist;
  twist.linear = Eigen::Vector3d(10.0, 0.0, 0.0);
  twist.angular = Eigen::Vector3d(0.0, 0.0, 0.5);
  const kitti::SweepClock clock = kitti::sweepClock(200.1, 200.0, true);
  const double target = 200.07;
  LidarCloud measured;
  std::vector<Eigen::Vector3d> scene;
  for (int k = 0; k < 36; ++k) {
    const double azimuth = (5.0 + 10.0 * k) * M_PI / 180.0;
    const Eigen::Vector3d X(8.0 * std::cos(azimuth), 8.0 * std::sin(azimuth), -1.0);
    // Solve p = pose(t)^-1 X with t = the time of p's azimuth (a fixed point; converges fast).
    Eigen::Vector3d p = X;
    for (int it = 0; it < 50; ++it) {
      const double dt = clock.stamp + kitti::azimuthTime(p.x(), p.y(), clock) - target;
      const Eigen::Isometry3d pose =
          Eigen::Translation3d(twist.linear * dt) *
          Eigen::AngleAxisd(twist.angular.norm() * dt, Eigen::Vector3d::UnitZ());
      p = pose.inverse() * X;
    }
    LidarPoint point;
    point.x = static_cast<float>(p.x());
    point.y = static_cast<float>(p.y());
    point.z = static_cast<float>(p.z());
    measured.push_back(point);
    scene.push_back(X);
  }
  LidarCloud deskewed = measured;
  kitti::deskewSweep(deskewed, clock, twist, target);
  double max_raw = 0.0, max_deskewed = 0.0;
  for (size_t k = 0; k < scene.size(); ++k) {
    const Eigen::Vector3d raw(measured[k].x, measured[k].y, measured[k].z);
    const Eigen::Vector3d out(deskewed[k].x, deskewed[k].y, deskewed[k].z);
    max_raw = std::max(max_raw, (raw - scene[k]).norm());
    max_deskewed = std::max(max_deskewed, (out - scene[k]).norm());
  }
  EXPECT_GT(max_raw, 0.5);        // up to 0.07 s * 10 m/s + the turn
  EXPECT_LT(max_deskewed, 2e-5);  // float coordinates
  // A standing sensor: nothing moves.
  LidarCloud standing = measured;
  kitti::deskewSweep(standing, clock, kitti::Twist{}, target);
  for (size_t k = 0; k < measured.size(); ++k) {
    EXPECT_EQ(standing[k].x, measured[k].x);
    EXPECT_EQ(standing[k].y, measured[k].y);
  }
  kitti::Twist bad;
  bad.linear.x() = NAN;
  EXPECT_THROW(kitti::deskewSweep(standing, clock, bad, target), std::invalid_argument);
}

}  // namespace
}  // namespace lidar_stereo_fusion
