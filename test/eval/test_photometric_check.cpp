// The photometric check on a synthetic rectified pair with a known sub-pixel disparity: a LiDAR
// disparity off by a known amount gives that amount back as the best shift; flat patches and
// shifts beyond the range are not scored; the summary's median and share are exact.
#include <cmath>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/eval/photometric_check.h"

namespace lidar_stereo_fusion {
namespace {

/// A smooth texture: sums of sines in x and y, grey levels 20 .. 235.
double texture(double x, double y) {
  return 127.5 + 40.0 * std::sin(0.9 * x + 0.3 * y) + 35.0 * std::sin(0.37 * x - 0.8 * y) +
         30.0 * std::sin(0.21 * x * 1.3 + 0.55 * y);
}

/// Left and right views of a fronto-parallel plane at disparity `d` [px]: right(x) = left(x + d).
void makePair(double d, cv::Mat& left, cv::Mat& right) {
  left.create(60, 120, CV_8UC1);
  right.create(60, 120, CV_8UC1);
  for (int y = 0; y < left.rows; ++y) {
    for (int x = 0; x < left.cols; ++x) {
      left.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(texture(x, y));
      right.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(texture(x + d, y));
    }
  }
}

TEST(PhotometricCheck, FindsAKnownSubPixelOffsetOfTheLidarDisparity) {
  const double true_d = 12.4;
  cv::Mat left, right;
  makePair(true_d, left, right);
  for (const double error : {0.0, 0.75, -1.3, 2.1}) {
    SCOPED_TRACE(error);
    cv::Mat1f sparse(left.size(), 0.f);
    for (int v = 10; v < 50; v += 7) {
      for (int u = 30; u < 110; u += 9) sparse(v, u) = static_cast<float>(true_d + error);
    }
    const PhotometricShifts result = photometricShifts(left, right, sparse);
    EXPECT_EQ(result.lidar_pixels, 6 * 9);
    EXPECT_EQ(result.unscored, 0);
    ASSERT_EQ(result.shifts.size(), 54u);
    // The match is at u - true_d = u - d + delta: delta = d - true_d = error.
    for (const double shift : result.shifts) EXPECT_NEAR(shift, error, 0.06);
    const ShiftSummary summary = summarizeShifts(result.shifts);
    EXPECT_NEAR(summary.median_abs, std::abs(error), 0.06);
    EXPECT_NEAR(summary.median, error, 0.06);
    EXPECT_EQ(summary.fraction_within, std::abs(error) <= 0.5 ? 1.0 : 0.0);
  }
}

TEST(PhotometricCheck, FlatPatchesEdgesAndOutOfRangeShiftsAreNotScored) {
  cv::Mat left, right;
  makePair(10.0, left, right);
  cv::Mat1f sparse(left.size(), 0.f);
  sparse(30, 1) = 10.f;    // patch leaves the image
  sparse(30, 60) = 12.f;   // the match is 2 px away: beyond the +-1 px searched here
  sparse(30, 80) = 10.5f;  // 0.5 px away: found
  PhotometricCheckParams narrow;
  narrow.max_shift = 1.0;
  PhotometricShifts result = photometricShifts(left, right, sparse, narrow);
  EXPECT_EQ(result.lidar_pixels, 3);
  EXPECT_EQ(result.unscored, 2);
  ASSERT_EQ(result.shifts.size(), 1u);
  EXPECT_NEAR(result.shifts[0], 0.5, 0.06);
  result = photometricShifts(left, right, sparse);  // +-3 px: the 2 px one is found too
  EXPECT_EQ(result.unscored, 1);
  const cv::Mat flat(left.size(), CV_8UC3, cv::Scalar::all(90));
  result = photometricShifts(flat, flat, sparse);
  EXPECT_EQ(result.unscored, 3);
  EXPECT_THROW(photometricShifts(left, right, cv::Mat1f(10, 10, 0.f)), std::invalid_argument);
  PhotometricCheckParams bad;
  bad.step = 0.0;
  EXPECT_THROW(photometricShifts(left, right, sparse, bad), std::invalid_argument);
}

TEST(PhotometricCheck, SummaryMedianAndShareAreExact) {
  const ShiftSummary s = summarizeShifts({-1.0, 0.25, 0.5, 2.0});
  EXPECT_EQ(s.count, 4);
  EXPECT_EQ(s.median, 0.375);
  EXPECT_EQ(s.median_abs, 0.75);
  EXPECT_EQ(s.fraction_within, 0.5);
  EXPECT_EQ(summarizeShifts({-0.75, 3.0, 0.1}).median_abs, 0.75);
  EXPECT_EQ(summarizeShifts({}).count, 0);
  const std::string table = formatShiftTable({{"f", s, s}, {"g", s, std::nullopt}});
  EXPECT_NE(table.find("| f | 4 | 0.375 | 0.750 | 50.0 % | 4 | 0.375 | 0.750 | 50.0 % |"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("| g | 4 | 0.375 | 0.750 | 50.0 % | - | - | - | - |"), std::string::npos)
      << table;
}

}  // namespace
}  // namespace lidar_stereo_fusion
