// Stage 1: projection (paper Eq. 1-2), z-buffer, right view, ring recovery. Exact answers on
// hand-placed points: every coordinate below is a binary-exact float so rounding is predictable.
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/lidar_projection.h"

namespace lidar_stereo_fusion {
namespace {

/// fx * B = 40: z = 8 m -> d = 5 px, z = 4 m -> d = 10 px, z = 16 m -> d = 2.5 px.
StereoCamera testCamera() {
  StereoCamera camera;
  camera.fx = 128.0;
  camera.fy = 64.0;
  camera.cx = 50.0;
  camera.cy = 40.0;
  camera.baseline = 0.3125;
  camera.width = 100;
  camera.height = 80;
  return camera;
}

LidarPoint point(float x, float y, float z, int ring = -1) {
  LidarPoint p;
  p.x = x;
  p.y = y;
  p.z = z;
  p.ring = ring;
  return p;
}

/// The optical-frame point whose projection is (u, v) at depth z with testCamera().
LidarPoint pointAt(double u, double v, double z, int ring = -1) {
  const StereoCamera c = testCamera();
  return point(static_cast<float>((u - c.cx) * z / c.fx), static_cast<float>((v - c.cy) * z / c.fy),
               static_cast<float>(z), ring);
}

int countNonZero(const cv::Mat1f& m) { return cv::countNonZero(m); }

TEST(Projection, HandPlacedPointsLandOnComputedPixelsWithExactDisparity) {
  const LidarCloud cloud = {point(1.0f, 0.5f, 8.0f, 3),      // u = 66, v = 44, d = 5
                            point(-2.0f, -1.0f, 4.0f, 7),    // u = -14 -> outside
                            point(-0.5f, -1.5f, 16.0f, 9)};  // u = 46, v = 34, d = 2.5
  const SparseDisparity s =
      projectCloud(cloud, Eigen::Isometry3d::Identity(), testCamera(), ProjectionParams());
  EXPECT_EQ(s.points_in_front, 3);
  EXPECT_EQ(s.points_in_image, 2);
  EXPECT_EQ(countNonZero(s.disparity), 2);
  EXPECT_EQ(s.disparity(44, 66), 5.0f);
  EXPECT_EQ(s.ring(44, 66), 3);
  EXPECT_EQ(s.disparity(34, 46), 2.5f);
  EXPECT_EQ(s.ring(34, 46), 9);
  EXPECT_EQ(s.ring(0, 0), -1);
}

TEST(Projection, RoundsToNearestPixelWithHalvesGoingUp) {
  // Pixel i covers [i - 0.5, i + 0.5): 60.5 -> 61, 60.25 -> 60, 60.75 -> 61, -0.5 -> 0.
  const LidarCloud cloud = {pointAt(60.5, 10.5, 8.0), pointAt(20.25, 20.75, 8.0),
                            pointAt(-0.5, 30.0, 8.0), pointAt(-0.75, 31.0, 8.0)};
  const SparseDisparity s =
      projectCloud(cloud, Eigen::Isometry3d::Identity(), testCamera(), ProjectionParams());
  EXPECT_EQ(s.disparity(11, 61), 5.0f);
  EXPECT_EQ(s.disparity(21, 20), 5.0f);
  EXPECT_EQ(s.disparity(30, 0), 5.0f);
  EXPECT_EQ(s.points_in_image, 3);  // u = -0.75 rounds to -1: outside
  EXPECT_EQ(countNonZero(s.disparity), 3);
}

TEST(Projection, ZBufferKeepsTheNearestPointInEitherOrder) {
  const LidarPoint far = point(1.0f, 0.5f, 8.0f, 1);    // (66, 44), d = 5
  const LidarPoint near = point(0.5f, 0.25f, 4.0f, 2);  // (66, 44), d = 10
  for (const LidarCloud& cloud : {LidarCloud{far, near}, LidarCloud{near, far}}) {
    const SparseDisparity s =
        projectCloud(cloud, Eigen::Isometry3d::Identity(), testCamera(), ProjectionParams());
    EXPECT_EQ(s.disparity(44, 66), 10.0f);
    EXPECT_EQ(s.ring(44, 66), 2);
    EXPECT_EQ(s.points_in_image, 2);
    EXPECT_EQ(countNonZero(s.disparity), 1);
  }
}

TEST(Projection, RightViewShiftsBySubPixelDisparityBeforeRounding) {
  // u_left = 66.25, d = 2.5 (z = 16): right column = round(63.75) = 64, not round(66.25) - 2.5.
  const LidarCloud cloud = {pointAt(66.25, 20.0, 16.0, 4), pointAt(30.0, 50.0, 8.0, 5)};
  const SparseDisparity left = projectCloud(cloud, Eigen::Isometry3d::Identity(), testCamera(),
                                            ProjectionParams(), View::kLeft);
  const SparseDisparity right = projectCloud(cloud, Eigen::Isometry3d::Identity(), testCamera(),
                                             ProjectionParams(), View::kRight);
  EXPECT_EQ(left.disparity(20, 66), 2.5f);
  EXPECT_EQ(right.disparity(20, 64), 2.5f);
  EXPECT_EQ(right.ring(20, 64), 4);
  EXPECT_EQ(right.disparity(50, 25), 5.0f);  // 30 - 5
  EXPECT_EQ(countNonZero(right.disparity), 2);
}

TEST(Projection, RightViewDropsPointsShiftedOutOfTheImage) {
  const LidarCloud cloud = {pointAt(3.0, 20.0, 4.0)};  // d = 10 -> right column -7
  const SparseDisparity right = projectCloud(cloud, Eigen::Isometry3d::Identity(), testCamera(),
                                             ProjectionParams(), View::kRight);
  EXPECT_EQ(right.points_in_front, 1);
  EXPECT_EQ(right.points_in_image, 0);
  EXPECT_EQ(countNonZero(right.disparity), 0);
}

TEST(Projection, DropsPointsBehindOutsideDepthRangeAndNonFinite) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  ProjectionParams params;
  params.min_depth = 1.0;
  params.max_depth = 50.0;
  const LidarCloud cloud = {point(0.f, 0.f, -8.f), point(0.f, 0.f, 0.f), point(0.f, 0.f, 0.5f),
                            point(0.f, 0.f, 64.f), point(nan, 0.f, 8.f), point(0.f, inf, 8.f),
                            point(0.f, 0.f, -inf), point(0.f, 0.f, 8.f), point(0.f, 0.f, 1.0f),
                            point(0.f, 0.f, 50.0f)};
  const SparseDisparity s =
      projectCloud(cloud, Eigen::Isometry3d::Identity(), testCamera(), params);
  EXPECT_EQ(s.points_in_front, 3);  // z = 8, and the inclusive limits z = 1 and z = 50
  EXPECT_EQ(s.points_in_image, 3);
  EXPECT_EQ(s.disparity(40, 50), 40.0f);  // z = 1: nearest of the three on (50, 40)
  for (float v : s.disparity) EXPECT_TRUE(std::isfinite(v));
}

TEST(Projection, FarOffCoordinatesAreDroppedWithoutIntegerOverflow) {
  const LidarCloud cloud = {point(1e30f, 0.f, 8.f), point(0.f, -1e30f, 8.f),
                            point(-3e38f, 3e38f, 8.f)};
  const SparseDisparity s =
      projectCloud(cloud, Eigen::Isometry3d::Identity(), testCamera(), ProjectionParams());
  EXPECT_EQ(s.points_in_front, 3);
  EXPECT_EQ(s.points_in_image, 0);
  EXPECT_EQ(countNonZero(s.disparity), 0);
}

TEST(Projection, AppliesTheLidarToCameraTransform) {
  // LiDAR axes x forward, y left, z up -> optical x right, y down, z forward, plus a translation.
  Eigen::Matrix3d R;
  R << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = Eigen::Vector3d(0.125, -0.25, 0.25);
  // Optical point (1, 0.5, 8) -> LiDAR (7.75, -0.875, -0.75).
  const LidarCloud cloud = {point(7.75f, -0.875f, -0.75f, 11)};
  const SparseDisparity s = projectCloud(cloud, T, testCamera(), ProjectionParams());
  EXPECT_EQ(s.disparity(44, 66), 5.0f);
  EXPECT_EQ(s.ring(44, 66), 11);
}

TEST(Projection, InvalidInputThrows) {
  const LidarCloud cloud = {point(0.f, 0.f, 8.f)};
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  StereoCamera camera = testCamera();
  camera.fx = 0.0;
  EXPECT_THROW(projectCloud(cloud, I, camera, ProjectionParams()), std::invalid_argument);
  camera = testCamera();
  camera.baseline = -0.5;
  EXPECT_THROW(projectCloud(cloud, I, camera, ProjectionParams()), std::invalid_argument);
  camera = testCamera();
  camera.width = 0;
  EXPECT_THROW(projectCloud(cloud, I, camera, ProjectionParams()), std::invalid_argument);
  camera = testCamera();
  camera.cy = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(projectCloud(cloud, I, camera, ProjectionParams()), std::invalid_argument);

  ProjectionParams params;
  params.min_depth = 0.0;
  EXPECT_THROW(projectCloud(cloud, I, testCamera(), params), std::invalid_argument);
  params = ProjectionParams();
  params.max_depth = params.min_depth;
  EXPECT_THROW(params.validate(), std::invalid_argument);

  Eigen::Isometry3d scaled = I;
  scaled.linear() *= 2.0;
  EXPECT_THROW(projectCloud(cloud, scaled, testCamera(), ProjectionParams()),
               std::invalid_argument);
  Eigen::Isometry3d broken = I;
  broken.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(projectCloud(cloud, broken, testCamera(), ProjectionParams()),
               std::invalid_argument);
  EXPECT_THROW(projectCloud({point(0.f, 0.f, 8.f, 40000)}, I, testCamera(), ProjectionParams()),
               std::invalid_argument);
}

TEST(Projection, CameraValidateNamesTheField) {
  StereoCamera camera = testCamera();
  camera.fy = -1.0;
  try {
    camera.validate();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fy"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(testCamera().validate());
}

/// A synthetic sweep in KITTI storage order: laser by laser, azimuth rising from just left of
/// straight ahead through the +-180 deg wrap to just right of straight ahead.
LidarCloud kittiLikeSweep(int lasers, int points_per_laser, bool jitter_at_start) {
  LidarCloud cloud;
  for (int laser = 0; laser < lasers; ++laser) {
    for (int i = 0; i < points_per_laser; ++i) {
      double azimuth_deg = 0.5 + 359.0 * i / (points_per_laser - 1);  // 0.5 .. 359.5
      if (jitter_at_start && i == 1) azimuth_deg = -0.1;  // jitter around 0 at the laser start
      if (jitter_at_start && i == 2) azimuth_deg = 0.3;
      const double a = azimuth_deg * M_PI / 180.0;  // atan2 maps 180..360 to -180..0
      const double range = 10.0 + laser;
      cloud.push_back(point(static_cast<float>(range * std::cos(a)),
                            static_cast<float>(range * std::sin(a)),
                            static_cast<float>(-0.1 * laser)));
    }
  }
  return cloud;
}

TEST(RingRecovery, SweepOrderStartsANewLaserAtTheUpwardZeroCrossing) {
  for (bool jitter : {false, true}) {
    SCOPED_TRACE(jitter ? "with azimuth jitter at laser starts" : "clean");
    LidarCloud cloud = kittiLikeSweep(5, 100, jitter);
    EXPECT_EQ(recoverRingsBySweepOrder(cloud), 5);
    for (std::size_t i = 0; i < cloud.size(); ++i) ASSERT_EQ(cloud[i].ring, int(i / 100)) << i;
    EXPECT_TRUE(hasRings(cloud));
  }
  LidarCloud empty;
  EXPECT_EQ(recoverRingsBySweepOrder(empty), 0);
}

TEST(RingRecovery, SweepOrderGivesNonFinitePointsTheirNeighboursRing) {
  LidarCloud cloud = kittiLikeSweep(2, 50, false);
  cloud[70].x = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(recoverRingsBySweepOrder(cloud), 2);
  EXPECT_EQ(cloud[70].ring, 1);
}

TEST(RingRecovery, ElevationFollowsNonUniformBeamsAndDoesNotInventRings) {
  const uint32_t seed = 20240611;
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> azimuth(-M_PI, M_PI), range(2.0, 80.0);
  // Dense centre beams 0.11 deg apart and sparse outer beams, as on a VLS-128.
  const std::vector<double> beams_deg = {-25.0, -11.75, -3.0, -2.89, -2.78, 0.0, 0.11, 15.0};
  LidarCloud cloud;
  std::vector<int> expected;
  for (int i = 0; i < 4000; ++i) {
    const int beam = i % static_cast<int>(beams_deg.size());
    const double e = beams_deg[beam] * M_PI / 180.0, a = azimuth(rng), r = range(rng);
    cloud.push_back(point(static_cast<float>(r * std::cos(e) * std::cos(a)),
                          static_cast<float>(r * std::cos(e) * std::sin(a)),
                          static_cast<float>(r * std::sin(e))));
    expected.push_back(beam);
  }
  cloud.push_back(point(std::numeric_limits<float>::quiet_NaN(), 0.f, 0.f));
  expected.push_back(-1);

  for (int asked : {8, 128}) {
    LidarCloud c = cloud;
    EXPECT_EQ(recoverRingsByElevation(c, asked), 8) << "asked " << asked;
    for (std::size_t i = 0; i < c.size(); ++i) ASSERT_EQ(c[i].ring, expected[i]) << i;
  }
  // Asking for fewer rings merges the beams separated by the narrowest gaps.
  LidarCloud merged = cloud;
  EXPECT_EQ(recoverRingsByElevation(merged, 3), 3);
  for (std::size_t i = 0; i + 1 < merged.size(); ++i) {
    const int want = expected[i] == 0 ? 0 : (expected[i] == 7 ? 2 : 1);
    ASSERT_EQ(merged[i].ring, want) << i;
  }
  LidarCloud bad = cloud;
  EXPECT_THROW(recoverRingsByElevation(bad, 0), std::invalid_argument);
  EXPECT_THROW(recoverRingsByElevation(bad, 8, -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace lidar_stereo_fusion
