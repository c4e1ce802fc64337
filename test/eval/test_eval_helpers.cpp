// The small evaluation helpers on synthetic input with exact answers: ring hold-out, row-sampled
// pseudo-LiDAR, metric tables.
#include <gtest/gtest.h>

#include "lidar_stereo_fusion/eval/holdout.h"
#include "lidar_stereo_fusion/eval/pseudo_lidar.h"
#include "lidar_stereo_fusion/eval/report.h"

#include "eval_test_scenes.h"

namespace lidar_stereo_fusion {
namespace {

/// 20 x 10, fx 100, principal point (10, 5), baseline 0.5 m (eval_test_scenes.h).
StereoCamera camera() { return test::camera(20, 10); }

LidarPoint point(float x, float y, float z, int ring) {
  LidarPoint p;
  p.x = x;
  p.y = y;
  p.z = z;
  p.ring = ring;
  return p;
}

TEST(RingHoldout, SplitsByRingParityAndRejectsPointsWithoutRing) {
  const LidarCloud cloud = {point(0, 0, 1, 0), point(0, 0, 2, 1), point(0, 0, 3, 2),
                            point(0, 0, 4, 5)};
  const RingSplit split = splitRingsEvenOdd(cloud);
  ASSERT_EQ(split.fed.size(), 2u);
  ASSERT_EQ(split.held_out.size(), 2u);
  EXPECT_EQ(split.fed[1].z, 3.f);
  EXPECT_EQ(split.held_out[1].ring, 5);
  EXPECT_THROW(splitRingsEvenOdd({point(0, 0, 1, -1)}), std::invalid_argument);
}

TEST(RingHoldout, KeepEveryFourFeedsRingsZeroFourEightAndRejectsKeepEveryBelowTwo) {
  LidarCloud cloud;
  for (int ring = 0; ring < 12; ++ring) cloud.push_back(point(0, 0, 1.f + ring, ring));
  const RingSplit split = splitRings(cloud, 4);
  ASSERT_EQ(split.fed.size(), 3u);
  EXPECT_EQ(split.fed[0].ring, 0);
  EXPECT_EQ(split.fed[1].ring, 4);
  EXPECT_EQ(split.fed[2].ring, 8);
  EXPECT_EQ(split.held_out.size(), 9u);
  for (const LidarPoint& p : split.held_out) EXPECT_NE(p.ring % 4, 0) << p.ring;
  EXPECT_THROW(splitRings(cloud, 1), std::invalid_argument);
  // The hold-out with keep_every 4 scores on rings 1-3: a point of ring 3 is the reference.
  const HoldoutCase holdout =
      makeRingHoldout({point(0, 0, 10, 0), point(0, 0, 5, 3)}, Eigen::Isometry3d::Identity(),
                      camera(), ProjectionParams(), 4);
  ASSERT_EQ(holdout.fed.size(), 1u);
  EXPECT_EQ(holdout.reference_depth(5, 10), 5.f);
  EXPECT_THROW(makeRingHoldout({point(0, 0, 10, 0), point(0, 0, 5, 4)},
                               Eigen::Isometry3d::Identity(), camera(), ProjectionParams(), 4),
               std::invalid_argument);  // ring 4 is fed: no reference left
}

TEST(RingHoldout, ReferenceDepthIsTheNearestZPerRoundedPixel) {
  // Identity transform: the LiDAR frame is the camera frame.
  const Eigen::Isometry3d identity = Eigen::Isometry3d::Identity();
  const LidarCloud held = {
      point(0.f, 0.f, 10.f, 1),     // u = 10, v = 5
      point(0.048f, 0.f, 8.f, 1),   // u = 10.6 -> 11, v = 5
      point(0.004f, 0.f, 9.f, 1),   // u = 10.04 -> 10: nearer than 10 m, wins
      point(-0.2f, -0.1f, 2.f, 1),  // u = 0, v = 0
      point(1.f, 0.f, 2.f, 1),      // u = 60: outside
      point(0.f, 0.f, 0.2f, 1),     // nearer than min_depth 0.5
      point(0.f, 0.f, -5.f, 1),     // behind
  };
  ProjectionParams params;
  const cv::Mat1f depth = projectReferenceDepth(held, identity, camera(), params);
  ASSERT_EQ(depth.size(), cv::Size(20, 10));
  EXPECT_EQ(depth(5, 10), 9.f);
  EXPECT_EQ(depth(5, 11), 8.f);
  EXPECT_EQ(depth(0, 0), 2.f);
  EXPECT_EQ(cv::countNonZero(depth), 3);
}

TEST(RingHoldout, MakeRingHoldoutFeedsEvenRingsAndFailsWithoutReference) {
  const Eigen::Isometry3d identity = Eigen::Isometry3d::Identity();
  const LidarCloud cloud = {point(0, 0, 10, 0), point(0, 0, 12, 1), point(0.1f, 0, 12, 2)};
  const HoldoutCase holdout = makeRingHoldout(cloud, identity, camera(), ProjectionParams());
  EXPECT_EQ(holdout.fed.size(), 2u);
  EXPECT_EQ(holdout.reference_depth(5, 10), 12.f);
  EXPECT_EQ(cv::countNonZero(holdout.reference_depth), 1);
  EXPECT_THROW(makeRingHoldout({point(0, 0, 10, 0)}, identity, camera(), ProjectionParams()),
               std::invalid_argument);
}

TEST(PseudoLidar, EvenlySpacedRowsWithRingIdsAndOnlyKnownDisparities) {
  cv::Mat1f gt(8, 5, 3.f);
  gt(1, 2) = 0.f;                                               // unknown: not sampled
  const SparseDisparity sparse = sampleRowsAsScanLines(gt, 4);  // rows 1, 3, 5, 7
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 5; ++x) {
      const bool sampled = y % 2 == 1 && !(y == 1 && x == 2);
      EXPECT_EQ(sparse.disparity(y, x), sampled ? 3.f : 0.f) << x << "," << y;
      EXPECT_EQ(sparse.ring(y, x), sampled ? y / 2 : -1) << x << "," << y;
    }
  }
  EXPECT_EQ(sparse.points_in_image, 19);
  EXPECT_THROW(sampleRowsAsScanLines(gt, 1), std::invalid_argument);
  EXPECT_THROW(sampleRowsAsScanLines(gt, 9), std::invalid_argument);
}

TEST(PseudoLidar, FirstRowSpreadsTheRowsOverTheLowerPartOnly) {
  // 12 rows, first row 4: rows 4 + floor((k + 0.5) * 8 / 4) = 5, 7, 9, 11.
  const cv::Mat1f gt(12, 3, 2.f);
  const SparseDisparity sparse = sampleRowsAsScanLines(gt, 4, 4);
  for (int y = 0; y < 12; ++y) {
    const bool sampled = y == 5 || y == 7 || y == 9 || y == 11;
    EXPECT_EQ(cv::countNonZero(sparse.disparity.row(y)), sampled ? 3 : 0) << y;
    if (sampled) {
      EXPECT_EQ(sparse.ring(y, 0), (y - 5) / 2) << y;
    }
  }
  EXPECT_EQ(scanLineRow(0, 4, 12, 4), 5);
  EXPECT_EQ(scanLineRow(3, 4, 12, 4), 11);
  EXPECT_EQ(scanLineRow(1, 3, 10, 0), 5);  // floor(1.5 * 10 / 3)
  // Default first row 0 keeps the old layout.
  EXPECT_EQ(cv::countNonZero(sampleRowsAsScanLines(gt, 4).disparity.row(1)), 3);
  EXPECT_THROW(sampleRowsAsScanLines(gt, 4, -1), std::invalid_argument);
  EXPECT_THROW(sampleRowsAsScanLines(gt, 2, 11), std::invalid_argument);
  EXPECT_THROW(sampleRowsAsScanLines(gt, 9, 4), std::invalid_argument);  // 8 rows below row 4
}

TEST(PseudoLidar, RightViewShiftsByTheRoundedDisparityAndTheNearerSampleWins) {
  SparseDisparity left;
  left.disparity = cv::Mat1f(1, 10, 0.f);
  left.ring = cv::Mat1s(1, 10, static_cast<int16_t>(-1));
  left.disparity(0, 5) = 2.4f;  // -> 2.6 -> 3
  left.ring(0, 5) = 7;
  left.disparity(0, 7) = 4.f;  // -> 3: nearer, wins
  left.ring(0, 7) = 8;
  left.disparity(0, 1) = 3.f;  // -> -2: outside
  const SparseDisparity right = shiftToRightView(left);
  EXPECT_EQ(right.disparity(0, 3), 4.f);
  EXPECT_EQ(right.ring(0, 3), 8);
  EXPECT_EQ(cv::countNonZero(right.disparity), 1);
  EXPECT_EQ(right.points_in_image, 2);
}

TEST(Report, TablesAndMedian) {
  DepthMetrics m;
  m.mae_mm = 302.4;
  m.rmse_mm = 1282.0;
  m.bad2 = 0.0452;
  m.count = 7;
  const std::string table = formatDepthTable({{"fused_bi", m}});
  EXPECT_NE(table.find("| fused_bi | 302 | 1282 |"), std::string::npos) << table;
  EXPECT_NE(table.find("| 4.52 |"), std::string::npos) << table;
  EXPECT_DOUBLE_EQ(median({3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(median({4, 1, 2, 3}), 2.5);
  EXPECT_DOUBLE_EQ(median({}), 0.0);
  FrameStats a, b, c;
  a.patchmatch_ms = 10;
  b.patchmatch_ms = 30;
  c.patchmatch_ms = 200;
  const std::string timing = formatTimingSummary({a, b, c});
  EXPECT_NE(timing.find("| PatchMatch | 80.0 | 30.0 |"), std::string::npos) << timing;
}

}  // namespace
}  // namespace lidar_stereo_fusion
