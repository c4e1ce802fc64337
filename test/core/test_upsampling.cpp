// Stage 2: BI* (scan-line completion, Algorithm 1, Eq. 3), BF* and the scan-line search bounds.
// Exact answers on hand-made maps: disparities are binary-exact so interpolation is exact.
#include <cmath>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/upsampling.h"

namespace lidar_stereo_fusion {
namespace {

SparseDisparity emptySparse(int rows, int cols) {
  SparseDisparity s;
  s.disparity = cv::Mat1f::zeros(rows, cols);
  s.ring = cv::Mat1s(rows, cols, static_cast<short>(-1));
  return s;
}

void addPoint(SparseDisparity& s, int x, int y, float d, short ring) {
  s.disparity(y, x) = d;
  s.ring(y, x) = ring;
}

ScanLines emptyLines(int rows, int cols) {
  ScanLines l;
  l.disparity = cv::Mat1f::zeros(rows, cols);
  l.ring = cv::Mat1s(rows, cols, static_cast<short>(-1));
  return l;
}

/// A full-width scan line at `row` with disparity d.
void addLine(ScanLines& l, int row, float d, short ring) {
  l.disparity.row(row).setTo(d);
  l.ring.row(row).setTo(ring);
}

cv::Mat uniformImage(int rows, int cols, cv::Vec3b color = {100, 100, 100}) {
  return cv::Mat(rows, cols, CV_8UC3, cv::Scalar(color[0], color[1], color[2]));
}

// ----------------------------------------------------------------------------------- completion

TEST(CompleteScanLines, InterpolatesExactValuesAlongALinearRamp) {
  SparseDisparity s = emptySparse(60, 40);
  addPoint(s, 10, 30, 10.f, 0);
  addPoint(s, 20, 40, 11.25f, 0);  // row +1 and disparity +0.125 per column
  const ScanLines l = completeScanLines(s, BIParams());
  for (int x = 10; x <= 20; ++x) {
    const int y = 30 + (x - 10);
    EXPECT_EQ(l.disparity(y, x), 10.f + 0.125f * (x - 10)) << "x " << x;
    EXPECT_EQ(l.ring(y, x), 0) << "x " << x;
  }
  EXPECT_EQ(cv::countNonZero(l.disparity), 11);
}

TEST(CompleteScanLines, RoundsTheInterpolatedRowHalfUp) {
  SparseDisparity s = emptySparse(20, 20);
  addPoint(s, 10, 5, 4.f, 2);
  addPoint(s, 14, 6, 4.f, 2);  // rows 5.25, 5.5, 5.75 -> 5, 6, 6
  const ScanLines l = completeScanLines(s, BIParams());
  EXPECT_EQ(l.disparity(5, 11), 4.f);
  EXPECT_EQ(l.disparity(6, 12), 4.f);
  EXPECT_EQ(l.disparity(6, 13), 4.f);
  EXPECT_EQ(cv::countNonZero(l.disparity), 5);
}

TEST(CompleteScanLines, DoesNotBridgeWideGapsOrDisparityJumps) {
  BIParams params;
  params.max_gap_px = 6;
  params.max_jump_disp = 2.0;
  SparseDisparity s = emptySparse(30, 60);
  addPoint(s, 0, 2, 10.f, 0);  // span 6 = max_gap_px: bridged
  addPoint(s, 6, 2, 10.f, 0);
  addPoint(s, 13, 2, 10.f, 0);  // span 7: not bridged
  addPoint(s, 0, 8, 10.f, 1);   // |delta d| = 2 = max_jump_disp: bridged
  addPoint(s, 4, 8, 12.f, 1);
  addPoint(s, 8, 8, 14.5f, 1);  // |delta d| = 2.5: not bridged
  const ScanLines l = completeScanLines(s, params);
  for (int x = 0; x <= 6; ++x) EXPECT_EQ(l.disparity(2, x), 10.f) << x;
  for (int x = 7; x < 13; ++x) EXPECT_EQ(l.disparity(2, x), 0.f) << x;
  EXPECT_EQ(l.disparity(2, 13), 10.f);
  for (int x = 0; x <= 4; ++x) EXPECT_EQ(l.disparity(8, x), 10.f + 0.5f * x) << x;
  for (int x = 5; x < 8; ++x) EXPECT_EQ(l.disparity(8, x), 0.f) << x;
  EXPECT_EQ(l.disparity(8, 8), 14.5f);
}

TEST(CompleteScanLines, ZBufferKeepsTheNearerLineWhereTwoLinesMeet) {
  // Ring 0 flat at row 20 (d = 5); ring 1 climbs from row 18 to 22, crossing row 20 at x = 5.
  for (float d1 : {8.f, 3.f}) {
    SCOPED_TRACE("ring 1 disparity " + std::to_string(d1));
    SparseDisparity s = emptySparse(40, 20);
    addPoint(s, 0, 20, 5.f, 0);
    addPoint(s, 10, 20, 5.f, 0);
    addPoint(s, 0, 18, d1, 1);
    addPoint(s, 10, 22, d1, 1);
    const ScanLines l = completeScanLines(s, BIParams());
    EXPECT_EQ(l.disparity(20, 5), std::max(5.f, d1));
    EXPECT_EQ(l.ring(20, 5), d1 > 5.f ? 1 : 0);
  }
}

TEST(CompleteScanLines, KeepsPointsWithoutRingAsSinglePixels) {
  SparseDisparity s = emptySparse(10, 20);
  addPoint(s, 2, 5, 7.f, -1);
  addPoint(s, 6, 5, 7.f, -1);
  const ScanLines l = completeScanLines(s, BIParams());
  EXPECT_EQ(cv::countNonZero(l.disparity), 2);
  EXPECT_EQ(l.disparity(5, 2), 7.f);
  EXPECT_EQ(l.ring(5, 2), -1);
}

TEST(CompleteScanLines, RejectsInvalidInput) {
  SparseDisparity s = emptySparse(10, 10);
  s.disparity(3, 3) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(completeScanLines(s, BIParams()), std::invalid_argument);
  s.disparity(3, 3) = -1.f;
  EXPECT_THROW(completeScanLines(s, BIParams()), std::invalid_argument);
  s = emptySparse(10, 10);
  s.ring = cv::Mat1s(5, 5, static_cast<short>(-1));
  EXPECT_THROW(completeScanLines(s, BIParams()), std::invalid_argument);
  EXPECT_THROW(completeScanLines(SparseDisparity(), BIParams()), std::invalid_argument);
}

// ---------------------------------------------------------------------------------- Algorithm 1

TEST(RemoveOccludedPoints, RemovesBackgroundLeakingBetweenForegroundLines) {
  ScanLines l = emptyLines(40, 30);
  addLine(l, 10, 20.f, 0);
  addLine(l, 15, 5.f, 1);  // far points the camera cannot see, same colour as the object
  addLine(l, 20, 20.f, 2);
  BIParams params;
  params.search_lines = 1;  // exactly the paper
  EXPECT_EQ(removeOccludedPoints(l, uniformImage(40, 30), params), 30);
  for (int x = 0; x < 30; ++x) {
    EXPECT_EQ(l.disparity(15, x), 0.f);
    EXPECT_EQ(l.ring(15, x), -1);
    EXPECT_EQ(l.disparity(10, x), 20.f);
    EXPECT_EQ(l.disparity(20, x), 20.f);
  }
}

TEST(RemoveOccludedPoints, KeepsBackgroundVisibleAboveAForegroundObject) {
  ScanLines l = emptyLines(40, 30);
  addLine(l, 10, 5.f, 0);  // background above the object: foreground only below
  addLine(l, 20, 20.f, 1);
  addLine(l, 30, 20.f, 2);
  EXPECT_EQ(removeOccludedPoints(l, uniformImage(40, 30), BIParams()), 0);
  EXPECT_EQ(cv::countNonZero(l.disparity), 90);
}

TEST(RemoveOccludedPoints, KeepsBackgroundWhoseColourDiffersFromTheForeground) {
  ScanLines l = emptyLines(40, 30);
  addLine(l, 10, 20.f, 0);
  addLine(l, 15, 5.f, 1);
  addLine(l, 20, 20.f, 2);
  cv::Mat image = uniformImage(40, 30);
  image.row(10).setTo(cv::Scalar(100, 100, 160));  // L1 distance 60 = max_color_diff: not "<"
  BIParams params;
  params.max_color_diff = 60.0;
  EXPECT_EQ(removeOccludedPoints(l, image, params), 0);
  image.row(10).setTo(cv::Scalar(100, 100, 159));  // 59 < 60: similar
  EXPECT_EQ(removeOccludedPoints(l, image, params), 30);
}

TEST(RemoveOccludedPoints, DisparityMarginIsStrict) {
  BIParams params;
  params.max_disp_diff = 1.5;
  for (float background : {18.5f, 18.25f}) {  // 20 - 18.5 = 1.5 (kept), 1.75 (removed)
    ScanLines l = emptyLines(30, 4);
    addLine(l, 5, 20.f, 0);
    addLine(l, 10, background, 1);
    addLine(l, 15, 20.f, 2);
    EXPECT_EQ(removeOccludedPoints(l, uniformImage(30, 4), params), background < 18.5f ? 4 : 0);
  }
}

TEST(RemoveOccludedPoints, SearchLinesReachPastASecondBackgroundLine) {
  auto make = [] {
    ScanLines l = emptyLines(40, 8);
    addLine(l, 10, 20.f, 0);
    addLine(l, 14, 5.f, 1);
    addLine(l, 16, 5.f, 2);
    addLine(l, 20, 20.f, 3);
    return l;
  };
  BIParams params;
  params.search_lines = 1;
  ScanLines paper = make();
  EXPECT_EQ(removeOccludedPoints(paper, uniformImage(40, 8), params), 0);
  params.search_lines = 2;
  ScanLines two = make();
  EXPECT_EQ(removeOccludedPoints(two, uniformImage(40, 8), params), 16);
  EXPECT_EQ(cv::countNonZero(two.disparity.row(14)), 0);
  EXPECT_EQ(cv::countNonZero(two.disparity.row(16)), 0);
}

TEST(RemoveOccludedPoints, DecidesOnTheInputStateNotOnEarlierRemovals) {
  // Row 13 (d 5) lies between 10 and 16 that are both nearer: removed. Row 16 (d 10) sees row 13
  // above, which is farther: kept. Had row 13 been cleared first, row 16 would see row 10 (d 20)
  // above and row 20 below and would be removed too; the pass must not depend on scan order.
  ScanLines l = emptyLines(30, 5);
  addLine(l, 10, 20.f, 0);
  addLine(l, 13, 5.f, 1);
  addLine(l, 16, 10.f, 2);
  addLine(l, 20, 20.f, 3);
  BIParams params;
  params.search_lines = 1;
  EXPECT_EQ(removeOccludedPoints(l, uniformImage(30, 5), params), 5);
  EXPECT_EQ(cv::countNonZero(l.disparity.row(13)), 0);
  EXPECT_EQ(cv::countNonZero(l.disparity.row(16)), 5);
}

TEST(RemoveOccludedPoints, GreyImagesCountEachGreyStepThreeTimes) {
  BIParams params;
  params.max_color_diff = 60.0;
  for (int step : {20, 19}) {  // 3 * 20 = 60 (not similar), 3 * 19 = 57 (similar)
    ScanLines l = emptyLines(30, 4);
    addLine(l, 5, 20.f, 0);
    addLine(l, 10, 5.f, 1);
    addLine(l, 15, 20.f, 2);
    cv::Mat1b grey(30, 4, static_cast<uint8_t>(100));
    grey.row(10).setTo(100 + step);
    EXPECT_EQ(removeOccludedPoints(l, grey, params), step == 19 ? 4 : 0);
  }
}

TEST(RemoveOccludedPoints, RejectsMismatchedImages) {
  ScanLines l = emptyLines(10, 10);
  EXPECT_THROW(removeOccludedPoints(l, uniformImage(10, 11), BIParams()), std::invalid_argument);
  EXPECT_THROW(removeOccludedPoints(l, cv::Mat(10, 10, CV_32FC3), BIParams()),
               std::invalid_argument);
  BIParams bad;
  bad.search_lines = 0;
  EXPECT_THROW(removeOccludedPoints(l, uniformImage(10, 10), bad), std::invalid_argument);
}

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
