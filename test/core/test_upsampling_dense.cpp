// Stage 2: BI* step 3 (Eq. 3) and the whole BI* chain, BF* and the scan-line search bounds.
// Exact answers on hand-made maps: disparities are binary-exact so interpolation is exact.
// Scan-line completion and Algorithm 1: test_upsampling.cpp.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/upsampling.h"
#include "upsampling_test_util.h"

namespace lidar_stereo_fusion {
namespace {

using namespace test;  // NOLINT: the maps of upsampling_test_util.h

// ---------------------------------------------------------------------------------------- Eq. 3

TEST(InterpolateBetweenScanLines, Equation3GivesExactValuesBetweenTwoLines) {
  ScanLines l = emptyLines(40, 6);
  addLine(l, 10, 20.f, 0);
  addLine(l, 20, 30.f, 1);
  const cv::Mat1f dense = interpolateBetweenScanLines(l, BIParams());
  for (int x = 0; x < 6; ++x) {
    for (int y = 0; y < 40; ++y) {
      const float want = (y < 10 || y > 20) ? 0.f : 20.f + (y - 10);
      ASSERT_EQ(dense(y, x), want) << "x " << x << " y " << y;
    }
  }
}

TEST(InterpolateBetweenScanLines, NonIntegerWeightsAndPerColumnLines) {
  ScanLines l = emptyLines(10, 2);
  l.disparity(0, 0) = 1.f;
  l.disparity(3, 0) = 2.f;
  l.disparity(2, 1) = 8.f;  // a single line in column 1: only its own pixel
  const cv::Mat1f dense = interpolateBetweenScanLines(l, BIParams());
  EXPECT_FLOAT_EQ(dense(1, 0), 4.f / 3.f);
  EXPECT_FLOAT_EQ(dense(2, 0), 5.f / 3.f);
  EXPECT_EQ(dense(4, 0), 0.f);
  EXPECT_EQ(dense(2, 1), 8.f);
  EXPECT_EQ(cv::countNonZero(dense.col(1)), 1);
}

TEST(InterpolateBetweenScanLines, DoesNotBridgeLinesTooFarApart) {
  BIParams params;
  params.max_interp_rows = 10;
  ScanLines l = emptyLines(60, 1);
  l.disparity(0, 0) = 10.f;
  l.disparity(10, 0) = 20.f;  // 10 rows apart: bridged
  l.disparity(21, 0) = 20.f;  // 11 rows apart: not bridged
  const cv::Mat1f dense = interpolateBetweenScanLines(l, params);
  EXPECT_EQ(dense(5, 0), 15.f);
  for (int y = 11; y < 21; ++y) EXPECT_EQ(dense(y, 0), 0.f) << y;
  EXPECT_EQ(dense(21, 0), 20.f);
}

TEST(UpsampleBI, ReproducesASlantedPlaneExactlyBetweenTheLines) {
  // d = 10 + 0.25 y + 0.125 x sampled every 4 columns on rings at rows 10, 20, 30: completion is
  // linear in x and Eq. 3 linear in y, so the plane comes back exactly between the lines.
  SparseDisparity s = emptySparse(40, 41);
  const int rows[] = {10, 20, 30};
  for (short r = 0; r < 3; ++r) {
    for (int x = 0; x <= 40; x += 4)
      addPoint(s, x, rows[r], 10.f + 0.25f * rows[r] + 0.125f * x, r);
  }
  int removed = -1;
  ScanLines lines;
  const cv::Mat1f dense = upsampleBI(s, uniformImage(40, 41), BIParams(), &removed, &lines);
  EXPECT_EQ(removed, 0);
  EXPECT_EQ(cv::countNonZero(lines.disparity), 3 * 41);
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x <= 40; ++x) {
      const float want = (y < 10 || y > 30) ? 0.f : 10.f + 0.25f * y + 0.125f * x;
      ASSERT_EQ(dense(y, x), want) << "x " << x << " y " << y;
    }
  }
}

TEST(UpsampleBI, RemovesTheLeakBeforeInterpolating) {
  SparseDisparity s = emptySparse(40, 20);
  for (int x = 0; x < 20; x += 2) {
    addPoint(s, x, 10, 20.f, 0);
    addPoint(s, x, 15, 4.f, 1);  // leaking background
    addPoint(s, x, 20, 20.f, 2);
  }
  int removed = 0;
  BIParams params;
  params.search_lines = 1;
  const cv::Mat1f dense = upsampleBI(s, uniformImage(40, 20), params, &removed);
  EXPECT_EQ(removed, 19);  // x = 0..18 completed, x = 19 has no point
  for (int x = 0; x <= 18; ++x) EXPECT_EQ(dense(15, x), 20.f) << x;
}

// ------------------------------------------------------------------------------------------ BF*

TEST(UpsampleBF, FillsAConstantPlaneExactly) {
  SparseDisparity s = emptySparse(50, 60);
  for (int y = 1; y < 50; y += 3) {
    for (int x = 0; x < 30; x += 3) s.disparity(y, x) = 7.3f;  // left half only
  }
  BFParams params;  // radius 6
  const cv::Mat1f dense = upsampleBF(s, params);
  for (int y = 0; y < 50; ++y) {
    for (int x = 0; x < 60; ++x) {
      const float want = x <= 27 + params.radius ? 7.3f : 0.f;
      ASSERT_EQ(dense(y, x), want) << "x " << x << " y " << y;
    }
  }
}

TEST(UpsampleBF, WeightsMatchSpatialTimesForegroundRangeGaussians) {
  SparseDisparity s = emptySparse(20, 20);
  s.disparity(10, 9) = 10.f;
  s.disparity(10, 11) = 9.f;
  BFParams params;
  params.sigma_space = 4.0;
  params.sigma_range = 2.0;
  const cv::Mat1f dense = upsampleBF(s, params);
  // At (10, 10) both points are 1 px away; reference = nearest = 10; w(9) = exp(-1 / 8).
  const double w = std::exp(-1.0 / 8.0);
  EXPECT_NEAR(dense(10, 10), (10.0 + w * 9.0) / (1.0 + w), 1e-5);
  // At (10, 7): spatial weights exp(-4/32) and exp(-16/32).
  const double ws9 = std::exp(-4.0 / 32.0), ws11 = std::exp(-16.0 / 32.0) * w;
  EXPECT_NEAR(dense(10, 7), (10.0 * ws9 + 9.0 * ws11) / (ws9 + ws11), 1e-5);
}

TEST(UpsampleBF, FavoursTheForegroundPoint) {
  SparseDisparity s = emptySparse(20, 20);
  s.disparity(10, 10) = 20.f;
  s.disparity(9, 9) = 5.f;
  s.disparity(11, 11) = 5.f;
  s.disparity(10, 12) = 5.f;
  const cv::Mat1f dense = upsampleBF(s, BFParams());
  EXPECT_NEAR(dense(10, 11), 20.f, 1e-5);
  EXPECT_NEAR(dense(10, 10), 20.f, 1e-5);
}

TEST(UpsampleBF, MinSupportLeavesSparselySupportedPixelsEmpty) {
  SparseDisparity s = emptySparse(20, 20);
  s.disparity(10, 10) = 8.f;
  BFParams params;
  params.radius = 2;
  params.min_support = 2;
  EXPECT_EQ(cv::countNonZero(upsampleBF(s, params)), 0);
  params.min_support = 1;
  EXPECT_EQ(cv::countNonZero(upsampleBF(s, params)), 25);
}

TEST(UpsampleBF, RejectsInvalidParamsAndInput) {
  const SparseDisparity s = emptySparse(10, 10);
  BFParams params;
  params.sigma_space = 0.0;
  EXPECT_THROW(upsampleBF(s, params), std::invalid_argument);
  params = BFParams();
  params.sigma_range = std::numeric_limits<double>::infinity();
  EXPECT_THROW(upsampleBF(s, params), std::invalid_argument);
  params = BFParams();
  params.min_support = 0;
  EXPECT_THROW(upsampleBF(s, params), std::invalid_argument);
  params = BFParams();
  params.radius = -1;
  EXPECT_THROW(upsampleBF(s, params), std::invalid_argument);
  params.radius = 100000;
  EXPECT_THROW(upsampleBF(s, params), std::invalid_argument);
  params = BFParams();
  params.sigma_range = 1e-320;
  EXPECT_THROW(upsampleBF(s, params), std::invalid_argument);
  SparseDisparity nan = emptySparse(10, 10);
  nan.disparity(2, 2) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(upsampleBF(nan, BFParams()), std::invalid_argument);
  EXPECT_THROW(upsampleBF(SparseDisparity(), BFParams()), std::invalid_argument);
}

TEST(BIParams, InvalidValuesThrow) {
  EXPECT_NO_THROW(BIParams().validate());
  BIParams p;
  p.max_gap_px = -1;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = BIParams();
  p.max_jump_disp = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = BIParams();
  p.max_disp_diff = -0.5;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = BIParams();
  p.max_color_diff = 0.0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = BIParams();
  p.max_interp_rows = 0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = BIParams();
  p.search_lines = 0;
  EXPECT_THROW(interpolateBetweenScanLines(emptyLines(4, 4), p), std::invalid_argument);
}

// --------------------------------------------------------------------------------------- bounds

TEST(ScanLineBounds, UsesTheNearestLinesStrictlyAboveAndBelow) {
  ScanLines l = emptyLines(30, 3);
  l.disparity(5, 0) = 10.f;
  l.disparity(15, 0) = 20.f;
  l.disparity(25, 0) = 18.f;
  l.disparity(12, 1) = 9.f;  // column 1: a single line -> unbounded
  const ScanLineBounds b = computeScanLineBounds(l, 1.0);
  for (int y = 0; y < 30; ++y) {
    SCOPED_TRACE("row " + std::to_string(y));
    float lo = 0.f, hi = 0.f, range = 0.f;
    if (y > 5 && y < 15) lo = 9.f, hi = 21.f, range = 10.f;
    if (y == 15) lo = 9.f, hi = 19.f, range = 8.f;  // on a line: the lines above and below it
    if (y > 15 && y < 25) lo = 17.f, hi = 21.f, range = 2.f;
    EXPECT_EQ(b.lo(y, 0), lo);
    EXPECT_EQ(b.hi(y, 0), hi);
    EXPECT_EQ(b.range(y, 0), range);
    for (int x = 1; x < 3; ++x) {
      EXPECT_EQ(b.lo(y, x), 0.f);
      EXPECT_EQ(b.hi(y, x), 0.f);
      EXPECT_EQ(b.range(y, x), 0.f);
    }
  }
  EXPECT_THROW(computeScanLineBounds(l, -1.0), std::invalid_argument);
  EXPECT_THROW(computeScanLineBounds(ScanLines(), 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace lidar_stereo_fusion
