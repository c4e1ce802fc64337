// Ego-motion compensation: interpolation of the sampled motion and the deskewed points of a rig
// moving past static points, with exact (to float rounding) answers.
#include <cmath>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/motion_compensation.h"

namespace lidar_stereo_fusion {
namespace {

LidarPoint pointAt(const Eigen::Vector3d& p, double time) {
  LidarPoint q;
  q.x = static_cast<float>(p.x());
  q.y = static_cast<float>(p.y());
  q.z = static_cast<float>(p.z());
  q.time = static_cast<float>(time);
  return q;
}

TEST(MotionCompensation, SampleTimesCoverTheSpanEvenly) {
  EXPECT_EQ(sampleTimes(-0.125, 0.0, 5),
            (std::vector<double>{-0.125, -0.09375, -0.0625, -0.03125, 0.0}));
  EXPECT_EQ(sampleTimes(0.0, 0.1, 1), (std::vector<double>{0.05}));
  EXPECT_EQ(sampleTimes(0.2, 0.2, 4), (std::vector<double>{0.2}));
  EXPECT_THROW(sampleTimes(0.0, 0.1, 0), std::invalid_argument);
  EXPECT_THROW(sampleTimes(0.1, 0.0, 3), std::invalid_argument);
}

TEST(MotionCompensation, InterpolatesBetweenSamplesAndHoldsOutside) {
  SweepMotion m;
  m.times = {0.0, 0.1};
  Eigen::Isometry3d b = Eigen::Isometry3d::Identity();
  b.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  b.translation() = Eigen::Vector3d(1.0, -2.0, 0.5);
  m.target_from_lidar = {Eigen::Isometry3d::Identity(), b};
  const Eigen::Isometry3d mid = m.at(0.05);
  EXPECT_TRUE(mid.translation().isApprox(Eigen::Vector3d(0.5, -1.0, 0.25), 1e-12));
  EXPECT_NEAR(Eigen::AngleAxisd(mid.linear()).angle(), 0.1, 1e-12);
  EXPECT_TRUE(m.at(-1.0).isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_TRUE(m.at(0.3).isApprox(b));
  EXPECT_TRUE(m.at(0.1).isApprox(b));
}

TEST(MotionCompensation, ValidateNamesTheProblem) {
  SweepMotion m;
  EXPECT_THROW(m.validate(), std::invalid_argument);
  m.times = {0.0, 0.0};
  m.target_from_lidar = {Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity()};
  try {
    m.validate();
    FAIL() << "equal times accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("increase"), std::string::npos) << e.what();
  }
  m.times = {0.0, 0.1};
  m.target_from_lidar[1].linear() *= 2.0;
  EXPECT_THROW(m.validate(), std::invalid_argument);
  m.target_from_lidar[1] = Eigen::Isometry3d::Identity();
  m.times[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(m.validate(), std::invalid_argument);
  LidarCloud cloud(1);
  m.times = {0.0};
  EXPECT_THROW(compensateMotion(cloud, m), std::invalid_argument);  // sizes differ
}

// A rig driving at 20 m/s along x past static points: the point measured at time t sits at
// W - v t in the LiDAR frame of that instant; compensated to the target instant 0.05 s it is
// W - v 0.05 exactly, whatever t was.
TEST(MotionCompensation, TranslationMovesEveryPointToTheTargetInstant) {
  const Eigen::Vector3d v(20.0, 0.0, 0.0);
  const double target = 0.05;
  const SweepMotion motion =
      constantVelocityMotion(v, Eigen::Vector3d::Zero(), target, sampleTimes(0.0, 0.1, 5));
  LidarCloud cloud;
  const std::vector<Eigen::Vector3d> world = {
      {10.0, 2.0, 0.5}, {-5.0, 3.0, 1.0}, {8.0, -4.0, -1.5}};
  const std::vector<double> times = {0.0, 0.0375, 0.1};
  for (size_t i = 0; i < world.size(); ++i)
    cloud.push_back(pointAt(world[i] - v * times[i], times[i]));
  compensateMotion(cloud, motion);
  for (size_t i = 0; i < world.size(); ++i) {
    const Eigen::Vector3d expected = world[i] - v * target;
    EXPECT_NEAR(cloud[i].x, expected.x(), 1e-5) << i;
    EXPECT_NEAR(cloud[i].y, expected.y(), 1e-5) << i;
    EXPECT_NEAR(cloud[i].z, expected.z(), 1e-5) << i;
    EXPECT_FLOAT_EQ(cloud[i].time, static_cast<float>(times[i]));  // times are kept
  }
}

// A rig turning in place at 1 rad/s about z: the point measured at time t, seen at yaw w t, comes
// back to where the LiDAR at the target instant (yaw 0) sees it.
TEST(MotionCompensation, RotationTurnsEveryPointToTheTargetInstant) {
  const Eigen::Vector3d w(0.0, 0.0, 1.0);
  const SweepMotion motion =
      constantVelocityMotion(Eigen::Vector3d::Zero(), w, 0.0, sampleTimes(-0.1, 0.0, 9));
  const Eigen::Vector3d world(10.0, 0.0, 1.0);
  LidarCloud cloud;
  for (const double t : {-0.1, -0.05, -0.0125, 0.0}) {
    // The LiDAR at t is yawed by w t from the target's: it sees the point rotated by -w t.
    const Eigen::Vector3d seen = Eigen::AngleAxisd(-t, Eigen::Vector3d::UnitZ()) * world;
    cloud.push_back(pointAt(seen, t));
  }
  LidarPoint nan_point;
  nan_point.x = std::numeric_limits<float>::quiet_NaN();
  cloud.push_back(nan_point);
  compensateMotion(cloud, motion);
  for (size_t i = 0; i + 1 < cloud.size(); ++i) {
    EXPECT_NEAR(cloud[i].x, world.x(), 1e-5) << i;
    EXPECT_NEAR(cloud[i].y, world.y(), 1e-5) << i;
  }
  EXPECT_TRUE(std::isnan(cloud.back().x));  // left as it was: the projection skips it
}

// The per-point path (nlerp) against at() (slerp) on a rig turning at 0.5 rad/s (a car's yaw rate
// in a tight bend) about a tilted axis while driving: 0.7 deg between samples, where nlerp and
// slerp differ by 3e-8 rad (1.5 um at 50 m); the points agree to float storage.
TEST(MotionCompensation, PerPointPathAgreesWithAt) {
  const SweepMotion motion =
      constantVelocityMotion(Eigen::Vector3d(15.0, 1.0, 0.2), Eigen::Vector3d(0.02, -0.05, 0.5),
                             -0.05, sampleTimes(-0.1, 0.0, 5));
  LidarCloud cloud;
  for (int i = 0; i <= 100; ++i) {
    const double t = -0.1 + 0.001 * i;
    cloud.push_back(pointAt(Eigen::Vector3d(50.0 * std::cos(i), 50.0 * std::sin(i), 1.5), t));
  }
  const LidarCloud before = cloud;
  compensateMotion(cloud, motion);
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d expected =
        motion.at(before[i].time) * Eigen::Vector3d(before[i].x, before[i].y, before[i].z);
    EXPECT_NEAR(cloud[i].x, expected.x(), 1e-5) << i;  // float storage of 50 m
    EXPECT_NEAR(cloud[i].y, expected.y(), 1e-5) << i;
    EXPECT_NEAR(cloud[i].z, expected.z(), 1e-5) << i;
  }
}

TEST(MotionCompensation, TimeSpanOfACloud) {
  LidarCloud cloud;
  EXPECT_EQ(timeSpan(cloud), (std::pair<double, double>{0.0, 0.0}));
  cloud.push_back(pointAt(Eigen::Vector3d::Ones(), 0.03));
  cloud.push_back(pointAt(Eigen::Vector3d::Ones(), -0.0625));
  cloud.push_back(pointAt(Eigen::Vector3d::Ones(), 0.0));
  EXPECT_EQ(timeSpan(cloud), (std::pair<double, double>{-0.0625, static_cast<double>(0.03f)}));
}

}  // namespace
}  // namespace lidar_stereo_fusion
