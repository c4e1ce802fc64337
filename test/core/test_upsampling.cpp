// Stage 2, BI* steps 1 and 2: scan-line completion and Algorithm 1 (removal of occluded points).
// Exact answers on hand-made maps: disparities are binary-exact so interpolation is exact.
// Eq. 3, the whole BI* chain, BF* and the search bounds: test_upsampling_dense.cpp.
#include <limits>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/upsampling.h"
#include "upsampling_test_util.h"

namespace lidar_stereo_fusion {
namespace {

using namespace test;  // NOLINT: the maps of upsampling_test_util.h

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
  params.step_fill = false;  // the paper's completion
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

// step_fill: across a jump larger than max_jump_disp (within max_gap_px) each side keeps its
// value up to the middle, the middle itself takes the nearer (larger d); the row is interpolated
// as for a smooth line; wide gaps stay gaps.
TEST(CompleteScanLines, AJumpWithinTheGapLimitBecomesAStepInTheMiddle) {
  BIParams params;
  params.max_gap_px = 6;
  params.max_jump_disp = 2.0;
  ASSERT_TRUE(params.step_fill);  // the default
  SparseDisparity s = emptySparse(30, 60);
  addPoint(s, 0, 8, 10.f, 1);  // |delta d| = 2 = max_jump_disp: interpolated
  addPoint(s, 4, 8, 12.f, 1);
  addPoint(s, 8, 8, 14.5f, 1);   // 2.5: a step, span 4 (even): x 5 -> 12, x 6 (middle) -> 14.5
  addPoint(s, 13, 10, 4.f, 1);   // span 5 (odd), rows 8 -> 10: x 9, 10 -> 14.5; 11, 12 -> 4
  addPoint(s, 20, 10, 30.f, 1);  // span 7 > max_gap_px: a gap
  const ScanLines l = completeScanLines(s, params);
  for (int x = 0; x <= 4; ++x) EXPECT_EQ(l.disparity(8, x), 10.f + 0.5f * x) << x;
  EXPECT_EQ(l.disparity(8, 5), 12.f);
  EXPECT_EQ(l.disparity(8, 6), 14.5f);
  EXPECT_EQ(l.disparity(8, 7), 14.5f);
  EXPECT_EQ(l.disparity(8, 8), 14.5f);
  // rows 8 + 2 t, t = 1/5 .. 4/5: 8.4, 8.8, 9.2, 9.6 round to 8, 9, 9, 10
  EXPECT_EQ(l.disparity(8, 9), 14.5f);
  EXPECT_EQ(l.disparity(9, 10), 14.5f);
  EXPECT_EQ(l.disparity(9, 11), 4.f);
  EXPECT_EQ(l.disparity(10, 12), 4.f);
  EXPECT_EQ(l.disparity(10, 13), 4.f);
  EXPECT_EQ(l.ring(8, 6), 1);
  for (int x = 14; x < 20; ++x) {
    for (int y = 0; y < 30; ++y) EXPECT_EQ(l.disparity(y, x), 0.f) << x << " " << y;
  }
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

}  // namespace
}  // namespace lidar_stereo_fusion
