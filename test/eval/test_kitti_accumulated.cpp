// The accumulated depth reference's rule (eval/kitti_accumulated.h, accumulateDepth) on a hand-made
// scene with exact answers: a wall at 10 m seen by the own sweep on every 4th row; the other
// sweep's points are kept when their depth lies within 5 % of the own depth range around them,
// removed when behind or in front of the wall or when no own point is near; the nearest point
// wins a pixel; the other sweep's pose is applied.
#include <gtest/gtest.h>

#include "lidar_stereo_fusion/eval/kitti_accumulated.h"

namespace lidar_stereo_fusion {
namespace {

StereoCamera camera() {
  StereoCamera c;
  c.fx = c.fy = 100.0;
  c.cx = c.cy = 10.0;
  c.baseline = 0.5;
  c.width = c.height = 21;
  return c;
}

/// A point [m, camera frame] that projects onto pixel (u, v) at depth z.
LidarPoint pointAt(int u, int v, float z) {
  LidarPoint p;
  p.x = (u - 10) * z / 100.f;
  p.y = (v - 10) * z / 100.f;
  p.z = z;
  return p;
}

/// The own sweep: the wall at 10 m on rows 2, 6, 10, 14, 18, columns 0..10.
kitti::PosedSweep ownWall() {
  kitti::PosedSweep own;
  own.own = true;
  own.T_cam_lidar = Eigen::Isometry3d::Identity();
  for (int v = 2; v < 21; v += 4) {
    for (int u = 0; u <= 10; ++u) own.cloud.push_back(pointAt(u, v, 10.f));
  }
  return own;
}

/// Another sweep whose frame is 2 m behind the camera (its points have z + 2 in its own frame).
kitti::PosedSweep other(const std::vector<LidarPoint>& camera_points) {
  kitti::PosedSweep s;
  s.T_cam_lidar = Eigen::Isometry3d(Eigen::Translation3d(0, 0, -2));
  for (LidarPoint p : camera_points) {
    p.z += 2.f;
    s.cloud.push_back(p);
  }
  return s;
}

TEST(AccumulatedDepth, KeepsPointsOnTheOwnSurfaceAndRemovesTheOthers) {
  const kitti::AccumulationParams params;  // window +-2 columns, +-3 rows, 5 %
  const std::vector<kitti::PosedSweep> sweeps = {
      ownWall(), other({pointAt(5, 4, 10.f),    // between rows 2 and 6, on the wall: kept
                        pointAt(4, 12, 10.4f),  // 4 % behind the wall: kept
                        pointAt(8, 8, 15.f),    // behind the wall: removed
                        pointAt(3, 12, 5.f),    // in front of the wall: removed
                        pointAt(16, 8, 10.f),   // no own point within 2 columns: removed
                        pointAt(7, 16, 10.2f),  // two points on one pixel: the nearer wins
                        pointAt(7, 16, 10.1f)})};
  const kitti::AccumulatedDepth out = kitti::accumulateDepth(sweeps, camera(), params);
  EXPECT_EQ(out.sweeps, 2);
  EXPECT_EQ(out.other_points, 7);
  EXPECT_EQ(out.removed_disagreeing, 2);
  EXPECT_EQ(out.removed_unverified, 1);
  EXPECT_EQ(out.own_pixels, 5 * 11);
  EXPECT_EQ(out.pixels, 5 * 11 + 3);
  EXPECT_NEAR(out.depth(4, 5), 10.f, 1e-5);
  EXPECT_NEAR(out.depth(12, 4), 10.4f, 1e-5);
  EXPECT_NEAR(out.depth(16, 7), 10.1f, 1e-5);
  EXPECT_EQ(out.depth(8, 8), 0.f);
  EXPECT_EQ(out.depth(12, 3), 0.f);
  EXPECT_EQ(out.depth(8, 16), 0.f);
  EXPECT_EQ(out.own(2, 0), 255);
  EXPECT_EQ(out.own(4, 5), 0);
  EXPECT_EQ(out.compared_pixels, 0);  // no other point on an own pixel
  kitti::AccumulationParams keep = params;
  keep.keep_unverified = true;
  const kitti::AccumulatedDepth kept = kitti::accumulateDepth(sweeps, camera(), keep);
  EXPECT_EQ(kept.removed_unverified, 1);  // still counted
  EXPECT_TRUE(kept.unverified_kept);
  EXPECT_FALSE(out.unverified_kept);
  EXPECT_EQ(kept.pixels, out.pixels + 1);
  EXPECT_NEAR(kept.depth(8, 16), 10.f, 1e-5);
}

TEST(AccumulatedDepth, ComparesTheOtherSweepsWithTheOwnOneBeforeRemoval) {
  // On own pixels: 2 % and 50 % (a point far behind, removed later but compared before).
  const std::vector<kitti::PosedSweep> sweeps = {
      ownWall(), other({pointAt(1, 6, 10.2f), pointAt(2, 6, 15.f), pointAt(3, 6, 10.f)})};
  const kitti::AccumulatedDepth out = kitti::accumulateDepth(sweeps, camera(), {});
  EXPECT_EQ(out.compared_pixels, 3);
  EXPECT_NEAR(out.median_relative_difference, 0.02, 1e-6);
  EXPECT_NEAR(out.p90_relative_difference, 0.02, 1e-6);  // the 90th of 3 values is the middle
  EXPECT_EQ(out.removed_disagreeing, 1);
  // The own point (10 m) and the other sweep's kept 10.2 m on one pixel: the nearer wins.
  EXPECT_NEAR(out.depth(6, 1), 10.f, 1e-5);
}

// Combine::kMajority: each sweep's point in a pixel is one vote; the largest group within 5 % wins
// (its median), the nearer between equal groups. A depth step of the own sweep (10 m left of
// column 6, 12 m from it) lets both depths pass the window check beside it.
TEST(AccumulatedDepth, MajorityTakesTheDepthMostSweepsAgreeOn) {
  kitti::PosedSweep own = ownWall();
  own.cloud.clear();
  for (int v = 2; v < 21; v += 4) {
    for (int u = 0; u <= 10; ++u) own.cloud.push_back(pointAt(u, v, u < 6 ? 10.f : 12.f));
  }
  const std::vector<kitti::PosedSweep> sweeps = {
      own, other({pointAt(6, 4, 10.f), pointAt(5, 8, 10.f), pointAt(6, 6, 10.f)}),
      other({pointAt(6, 4, 12.f), pointAt(5, 8, 12.f), pointAt(6, 6, 12.2f)}),
      other({pointAt(6, 4, 12.1f)})};
  kitti::AccumulationParams params;
  const kitti::AccumulatedDepth nearest = kitti::accumulateDepth(sweeps, camera(), params);
  params.combine = kitti::AccumulationParams::Combine::kMajority;
  const kitti::AccumulatedDepth majority = kitti::accumulateDepth(sweeps, camera(), params);
  EXPECT_EQ(nearest.removed_disagreeing + nearest.removed_unverified, 0);
  EXPECT_EQ(majority.pixels, nearest.pixels);
  EXPECT_NEAR(nearest.depth(4, 6), 10.f, 1e-5);
  EXPECT_NEAR(majority.depth(4, 6), 12.05f, 1e-5);  // 12.0 and 12.1 against 10.0
  EXPECT_NEAR(nearest.depth(8, 5), 10.f, 1e-5);
  EXPECT_NEAR(majority.depth(8, 5), 10.f, 1e-5);  // one vote each: the nearer
  EXPECT_NEAR(nearest.depth(6, 6), 10.f, 1e-5);
  EXPECT_NEAR(majority.depth(6, 6), 12.1f, 1e-5);  // own 12.0, 12.2 against 10.0: the median
  EXPECT_NEAR(majority.depth(2, 0), 10.f, 1e-5);   // the own sweep alone
}

TEST(AccumulatedDepth, NeedsExactlyOneOwnSweep) {
  kitti::PosedSweep a = ownWall(), b = ownWall();
  EXPECT_THROW(kitti::accumulateDepth({a, b}, camera(), {}), std::invalid_argument);
  a.own = b.own = false;
  EXPECT_THROW(kitti::accumulateDepth({a, b}, camera(), {}), std::invalid_argument);
  kitti::AccumulationParams params;
  params.tolerance = 1.0;
  EXPECT_THROW(kitti::accumulateDepth({ownWall()}, camera(), params), std::invalid_argument);
}

}  // namespace
}  // namespace lidar_stereo_fusion
