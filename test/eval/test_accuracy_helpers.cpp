// The accuracy protocols' helpers on hand-made maps with exact answers: nearest-LiDAR fill, map
// combination, region masks, layouts.
#include <algorithm>
#include <limits>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/eval/accuracy_protocols.h"

namespace lidar_stereo_fusion {
namespace {

bool equal(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && cv::countNonZero(a != b) == 0;
}

TEST(NearestFill, EveryPixelTakesTheEuclideanNearestValue) {
  cv::Mat1f fed(5, 7, 0.f);
  fed(0, 0) = 1.f;
  fed(4, 6) = 2.f;
  fed(2, 3) = 3.f;
  const cv::Mat1f out = nearestFill(fed);
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 7; ++x) {
      // Squared distances to the three points; no ties in this layout except where noted below.
      const int d1 = y * y + x * x, d2 = (y - 4) * (y - 4) + (x - 6) * (x - 6),
                d3 = (y - 2) * (y - 2) + (x - 3) * (x - 3);
      const int best = std::min({d1, d2, d3});
      const int ties = (d1 == best) + (d2 == best) + (d3 == best);
      if (ties > 1) continue;
      const float expected = d1 == best ? 1.f : d2 == best ? 2.f : 3.f;
      EXPECT_EQ(out(y, x), expected) << x << "," << y;
    }
  }
  // Euclidean, not city-block: (6, 0) is at 13 from the centre point and 16 from (6, 4).
  EXPECT_EQ(out(0, 6), 3.f);
}

TEST(NearestFill, DiagonalBeatsAStraightLineThatIsLongerInEuclideanDistance) {
  // (0, 0) -> point A at (3, 3) has d^2 = 18; point B at (0, 5) has d^2 = 25 (city-block 6 vs 5).
  cv::Mat1f fed(8, 8, 0.f);
  fed(3, 3) = 7.f;
  fed(5, 0) = 9.f;
  EXPECT_EQ(nearestFill(fed)(0, 0), 7.f);
  EXPECT_EQ(nearestFill(cv::Mat1f(3, 3, 0.f)).at<float>(1, 1), 0.f);  // nothing to copy
  EXPECT_THROW(nearestFill(cv::Mat1f()), std::invalid_argument);
}

TEST(CombineMaps, PrimaryWhereItHasAValueFallbackElsewhere) {
  const cv::Mat1f primary = (cv::Mat1f(1, 4) << 1, 0, 3, -1);
  const cv::Mat1f fallback = (cv::Mat1f(1, 4) << 5, 6, 0, 0);
  EXPECT_TRUE(equal(combineMaps(primary, fallback), (cv::Mat1f(1, 4) << 1, 6, 3, 0)));
  EXPECT_THROW(combineMaps(primary, cv::Mat1f(2, 4, 0.f)), std::invalid_argument);
}

/// Two horizontal scan lines (rings 0, 1) on rows 2 and 6 of a 9x4 image, grey image.
SparseDisparity twoLines(float upper, float lower) {
  SparseDisparity s;
  s.disparity = cv::Mat1f(9, 4, 0.f);
  s.ring = cv::Mat1s(9, 4, static_cast<int16_t>(-1));
  for (int x = 0; x < 4; ++x) {
    s.disparity(2, x) = upper;
    s.ring(2, x) = 0;
    s.disparity(6, x) = lower;
    s.ring(6, x) = 1;
  }
  return s;
}

TEST(RegionMasks, AboveInsideEdgeAndElsewhere) {
  SparseDisparity s = twoLines(10.f, 20.f);  // |20 - 10| > 3: the rows between are "edge"
  s.disparity(2, 0) = 0.f;                   // column 0's topmost fed pixel is then on row 6
  s.ring(2, 0) = -1;
  const cv::Mat image(9, 4, CV_8UC1, cv::Scalar(0));
  const RegionMasks m = computeRegionMasks(s, image);
  for (int y = 0; y < 9; ++y) {
    for (int x = 0; x < 4; ++x) {
      const int top = x == 0 ? 6 : 2;
      EXPECT_EQ(m.above(y, x) > 0, y < top) << x << "," << y;
      EXPECT_EQ(m.inside(y, x) > 0, y >= top) << x << "," << y;
    }
  }
  // Column 0 has a line on row 6 only: none of its pixels lies between two lines, so no edge.
  EXPECT_EQ(cv::countNonZero(m.edge.col(0)), 0);
  EXPECT_EQ(cv::countNonZero(m.elsewhere.col(0)), 3);  // rows 6-8
  for (int x = 1; x < 4; ++x) {
    for (int y = 0; y < 9; ++y) {
      const bool edge = y > 2 && y < 6;
      EXPECT_EQ(m.edge(y, x) > 0, edge) << x << "," << y;
      EXPECT_EQ(m.elsewhere(y, x) > 0, !edge && y >= 2) << x << "," << y;
    }
  }
  EXPECT_TRUE(m.mask(Region::kAll).empty());
  EXPECT_EQ(regionName(Region::kElsewhere), "elsewhere");
}

TEST(RegionMasks, LinesWithinThreePixelsMakeNoEdge) {
  const RegionMasks m = computeRegionMasks(twoLines(10.f, 13.f), cv::Mat(9, 4, CV_8UC1, 0.0));
  EXPECT_EQ(cv::countNonZero(m.edge), 0);  // range 3 is not > 3
  EXPECT_EQ(cv::countNonZero(m.elsewhere), 7 * 4);
  EXPECT_THROW(computeRegionMasks(twoLines(1, 2), cv::Mat(8, 4, CV_8UC1, 0.0)),
               std::invalid_argument);
}

TEST(RegionMasks, DepthBandsSplitTheReferenceAtTenAndThirtyMetres) {
  RegionMasks m = computeRegionMasks(twoLines(10.f, 13.f), cv::Mat(9, 4, CV_8UC1, 0.0));
  EXPECT_EQ(cv::countNonZero(m.near) + cv::countNonZero(m.mid) + cv::countNonZero(m.far), 0);
  cv::Mat1f reference(9, 4, 0.f);
  reference(0, 0) = 9.999f;
  reference(0, 1) = 10.f;  // 10 m is in 10-30
  reference(0, 2) = 29.99f;
  reference(0, 3) = 30.f;                                     // 30 m is in >= 30
  reference(8, 3) = std::numeric_limits<float>::quiet_NaN();  // no reference
  m.setDepthBands(reference);
  EXPECT_EQ(cv::countNonZero(m.near), 1);
  EXPECT_EQ(m.near(0, 0), 255);
  EXPECT_EQ(cv::countNonZero(m.mid), 2);
  EXPECT_EQ(m.mid(0, 1), 255);
  EXPECT_EQ(m.mid(0, 2), 255);
  EXPECT_EQ(cv::countNonZero(m.far), 1);
  EXPECT_EQ(m.far(0, 3), 255);
  EXPECT_EQ(&m.mask(Region::kMid), &m.mid);
  EXPECT_EQ(regionName(Region::kNear), "< 10 m");
  EXPECT_EQ(regionName(Region::kFar), ">= 30 m");
  EXPECT_THROW(m.setDepthBands(cv::Mat1f(8, 4, 0.f)), std::invalid_argument);
}

TEST(RegionMasks, TopRowsAreTheRowsAboveRow150OnceTheBandsAreSet) {
  RegionMasks m = computeRegionMasks(twoLines(10.f, 13.f), cv::Mat(9, 4, CV_8UC1, 0.0));
  EXPECT_EQ(cv::countNonZero(m.top_rows), 0);  // empty until the reference is known
  m.setDepthBands(cv::Mat1f(9, 4, 20.f));
  EXPECT_EQ(cv::countNonZero(m.top_rows), 9 * 4);  // a 9-row image lies above row 150
  EXPECT_EQ(&m.mask(Region::kTopRows), &m.top_rows);
  EXPECT_EQ(regionName(Region::kTopRows), "rows < 150");
  RegionMasks tall = computeRegionMasks(twoLines(10.f, 13.f), cv::Mat(9, 4, CV_8UC1, 0.0));
  tall.above = cv::Mat1b(200, 3, uchar(0));  // the bands take the masks' size from `above`
  tall.setDepthBands(cv::Mat1f(200, 3, 0.f));
  EXPECT_EQ(cv::countNonZero(tall.top_rows), kTopRowsEnd * 3);
  EXPECT_EQ(tall.top_rows(kTopRowsEnd - 1, 2), 255);
  EXPECT_EQ(tall.top_rows(kTopRowsEnd, 0), 0);
}

TEST(RegionMasks, AboveInBothViewsIsWhereTheMatchLiesInsideTheRightImage) {
  RegionMasks m = computeRegionMasks(twoLines(10.f, 13.f), cv::Mat(9, 4, CV_8UC1, 0.0));
  EXPECT_EQ(cv::countNonZero(m.above_both_views), 0);         // empty until the reference is known
  cv::Mat1f reference(9, 4, 2.f);                             // x - 2 >= 0 from column 2 on
  reference(0, 3) = 3.f;                                      // x - d = 0: the match is column 0
  reference(1, 3) = 3.5f;                                     // x - d < 0: outside the right image
  reference(1, 2) = std::numeric_limits<float>::quiet_NaN();  // no reference
  reference(4, 3) = 1.f;                                      // below the top line: not "above"
  m.setInBothViews(reference);
  // "above" is rows 0-1; of those, columns 2-3 except (1, 2) and (1, 3).
  EXPECT_EQ(cv::countNonZero(m.above_both_views), 2);
  EXPECT_EQ(m.above_both_views(0, 2), 255);
  EXPECT_EQ(m.above_both_views(0, 3), 255);
  EXPECT_EQ(&m.mask(Region::kAboveBothViews), &m.above_both_views);
  EXPECT_EQ(regionName(Region::kAboveBothViews), "above, both views");
  EXPECT_THROW(m.setInBothViews(cv::Mat1f(8, 4, 0.f)), std::invalid_argument);
}

TEST(AccuracyLayouts, MiddleburyRowsAndKittiKeepEvery) {
  const cv::Mat1f gt(90, 5, 4.f);
  EXPECT_EQ(cv::countNonZero(middleburyLayout(gt, "mb64").disparity), 64 * 5);
  const SparseDisparity low = middleburyLayout(gt, "mb42low");
  EXPECT_EQ(cv::countNonZero(low.disparity.rowRange(0, 30)), 0);  // 90 / 3 = 30
  EXPECT_EQ(cv::countNonZero(low.disparity.row(30)), 5);          // 30 + floor(0.5 * 60 / 42)
  EXPECT_EQ(cv::countNonZero(low.disparity.row(89)), 5);          // 30 + floor(41.5 * 60 / 42)
  EXPECT_EQ(kittiKeepEvery("ring32"), 2);
  EXPECT_EQ(kittiKeepEvery("ring16"), 4);
  EXPECT_THROW(middleburyLayout(gt, "mb8"), std::invalid_argument);
  EXPECT_THROW(kittiKeepEvery("ring8"), std::invalid_argument);
  AccuracyOptions options;
  options.methods = {"fused", "nearest", "ip_basic"};
  options.layouts = {"ring32", "dense"};
  EXPECT_NO_THROW(options.validate());
  options.layouts = {"dense64"};
  EXPECT_THROW(options.validate(), std::invalid_argument);
  options.layouts.clear();
  options.methods = {"fast"};
  EXPECT_THROW(options.validate(), std::invalid_argument);
  options.methods.clear();
  options.ip_basic.dilation_kernel = 4;
  EXPECT_THROW(options.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace lidar_stereo_fusion
