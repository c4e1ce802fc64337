// KITTI depth-completion metrics and disparity bad-pixel rates on hand-computed examples.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/metrics.h"
#include "test_scenes.h"

namespace lidar_stereo_fusion {
namespace {

/// fx * B = 100 px m.
StereoCamera camera(int width, int height) { return test::centredCamera(width, height, 200.0); }

TEST(DepthMetrics, MaeRmseAndInverseErrorsOverReferencePixelsMissingCountsAsZeroDepth) {
  const cv::Mat1f reference = (cv::Mat1f(2, 3) << 10, 20, 0, 5, 25, 50);
  const cv::Mat1f estimate = (cv::Mat1f(2, 3) << 11, 18, 7, 0, 25, 40);
  const DepthMetrics m = evaluateDepth(estimate, reference, camera(3, 2));
  // Depth errors [m]: 1, 2, 5 (missing: z_ref), 0, 10 over 5 pixels; the 7 has no reference.
  EXPECT_EQ(m.count, 5);
  EXPECT_NEAR(m.mae_mm, 1000.0 * 18.0 / 5.0, 1e-9);
  EXPECT_NEAR(m.rmse_mm, 1000.0 * std::sqrt(130.0 / 5.0), 1e-9);
  // Inverse errors [1/m]: 1/110, 1/180, 1/5 (missing: 1/z_ref), 0, 1/200.
  const double inv[] = {1.0 / 110, 1.0 / 180, 1.0 / 5, 0.0, 1.0 / 200};
  double sum = 0, sq = 0;
  for (double e : inv) {
    sum += e;
    sq += e * e;
  }
  EXPECT_NEAR(m.imae_per_km, 1000.0 * sum / 5, 1e-9);
  EXPECT_NEAR(m.irmse_per_km, 1000.0 * std::sqrt(sq / 5), 1e-9);
  // Disparity errors [px] (fx B = 100): 0.909, 0.556, 20 (missing), 0, 0.5.
  EXPECT_DOUBLE_EQ(m.bad2, 0.2);
  EXPECT_DOUBLE_EQ(m.bad3, 0.2);
  EXPECT_DOUBLE_EQ(m.bad5, 0.2);
  EXPECT_DOUBLE_EQ(m.coverage, 0.8);
}

TEST(DepthMetrics, OnlyCoveredSkipsMissingEstimatesButReportsCoverageOfAllPixels) {
  const cv::Mat1f reference = (cv::Mat1f(2, 3) << 10, 20, 0, 5, 25, 50);
  const cv::Mat1f estimate = (cv::Mat1f(2, 3) << 11, 18, 7, 0, 25, 40);
  const DepthMetrics m = evaluateDepth(estimate, reference, camera(3, 2), true);
  EXPECT_EQ(m.count, 4);
  EXPECT_NEAR(m.mae_mm, 1000.0 * 13.0 / 4.0, 1e-9);
  EXPECT_NEAR(m.rmse_mm, 1000.0 * std::sqrt(105.0 / 4.0), 1e-9);
  EXPECT_DOUBLE_EQ(m.bad2, 0.0);
  EXPECT_DOUBLE_EQ(m.coverage, 0.8);
}

TEST(DepthMetrics, BadPixelRatesUseDisparityAndStrictThresholds) {
  // Reference disparity 10 px everywhere (z = 10 m); estimates with disparity errors
  // 2.5, 3.5, 6 and 1.9 px.
  const cv::Mat1f reference(1, 4, 10.f);
  const cv::Mat1f estimate =
      (cv::Mat1f(1, 4) << 100.f / 12.5f, 100.f / 13.5f, 100.f / 16.f, 100.f / 11.9f);
  const DepthMetrics m = evaluateDepth(estimate, reference, camera(4, 1));
  EXPECT_DOUBLE_EQ(m.bad2, 0.75);
  EXPECT_DOUBLE_EQ(m.bad3, 0.5);
  EXPECT_DOUBLE_EQ(m.bad5, 0.25);
}

TEST(DepthMetrics, NanMarksNoValueInBothMapsAndEmptyReferenceGivesZeroCount) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const cv::Mat1f reference = (cv::Mat1f(1, 3) << nan, 10, 0);
  const cv::Mat1f estimate = (cv::Mat1f(1, 3) << 5, nan, 3);
  const DepthMetrics m = evaluateDepth(estimate, reference, camera(3, 1));
  EXPECT_EQ(m.count, 1);
  EXPECT_NEAR(m.mae_mm, 10000.0, 1e-9);
  EXPECT_DOUBLE_EQ(m.coverage, 0.0);
  const DepthMetrics none = evaluateDepth(estimate, cv::Mat1f(1, 3, 0.f), camera(3, 1));
  EXPECT_EQ(none.count, 0);
  EXPECT_EQ(none.mae_mm, 0.0);
}

TEST(DepthMetrics, SizeMismatchAndInvalidCameraAreErrors) {
  EXPECT_THROW(evaluateDepth(cv::Mat1f(2, 3, 1.f), cv::Mat1f(3, 2, 1.f), camera(3, 2)),
               std::invalid_argument);
  StereoCamera bad = camera(3, 2);
  bad.baseline = 0;
  EXPECT_THROW(evaluateDepth(cv::Mat1f(2, 3, 1.f), cv::Mat1f(2, 3, 1.f), bad),
               std::invalid_argument);
}

TEST(DisparityMetrics, ErrorsOverReferencePixelsMissingCountsAsFullDisparity) {
  const cv::Mat1f reference = (cv::Mat1f(1, 4) << 10, 0, 5, 8);
  const cv::Mat1f estimate = (cv::Mat1f(1, 4) << 10.5, 3, 0, 4);
  const DisparityMetrics m = evaluateDisparity(estimate, reference);
  // Errors: 0.5, 5 (missing), 4 over 3 pixels.
  EXPECT_EQ(m.count, 3);
  EXPECT_NEAR(m.mae_px, 9.5 / 3, 1e-12);
  EXPECT_NEAR(m.rmse_px, std::sqrt(41.25 / 3), 1e-12);
  EXPECT_DOUBLE_EQ(m.bad1, 2.0 / 3);
  EXPECT_DOUBLE_EQ(m.bad2, 2.0 / 3);
  EXPECT_DOUBLE_EQ(m.bad3, 2.0 / 3);
  EXPECT_DOUBLE_EQ(m.bad5, 0.0);  // 5 is not > 5
  EXPECT_DOUBLE_EQ(m.coverage, 2.0 / 3);
  EXPECT_THROW(evaluateDisparity(cv::Mat1f(1, 3, 1.f), reference), std::invalid_argument);
}

TEST(AverageMetrics, EveryImageWeighsTheSameAndEmptyImagesAreSkipped) {
  DepthMetrics a, b, empty;
  a.mae_mm = 1000;
  a.rmse_mm = 2000;
  a.bad2 = 0.1;
  a.coverage = 1.0;
  a.count = 10;
  b.mae_mm = 3000;
  b.rmse_mm = 4000;
  b.bad2 = 0.3;
  b.coverage = 0.5;
  b.count = 1000;
  empty.mae_mm = 1e9;  // count 0: ignored
  const DepthMetrics mean = averageMetrics(std::vector<DepthMetrics>{a, b, empty});
  EXPECT_DOUBLE_EQ(mean.mae_mm, 2000);
  EXPECT_DOUBLE_EQ(mean.rmse_mm, 3000);
  EXPECT_DOUBLE_EQ(mean.bad2, 0.2);
  EXPECT_DOUBLE_EQ(mean.coverage, 0.75);
  EXPECT_EQ(mean.count, 1010);
  EXPECT_EQ(averageMetrics(std::vector<DepthMetrics>{}).count, 0);

  DisparityMetrics c, d;
  c.mae_px = 1;
  c.bad1 = 0.5;
  c.count = 3;
  d.mae_px = 2;
  d.bad1 = 0.25;
  d.count = 5;
  const DisparityMetrics dm = averageMetrics(std::vector<DisparityMetrics>{c, d});
  EXPECT_DOUBLE_EQ(dm.mae_px, 1.5);
  EXPECT_DOUBLE_EQ(dm.bad1, 0.375);
  EXPECT_EQ(dm.count, 8);
}

// fillLikeDevkit: the loops of the KITTI devkit's interpolateBackground (io_depth.h).
TEST(FillLikeDevkit, RowGapTakesTheNearerValueAndRowEndsAreExtended) {
  const cv::Mat1f depth = (cv::Mat1f(1, 7) << 0, 5, 0, 0, 9, 0, 0);
  const cv::Mat1f filled = fillLikeDevkit(depth, MapKind::kDepth);
  const cv::Mat1f expected = (cv::Mat1f(1, 7) << 5, 5, 5, 5, 9, 9, 9);  // min depth = nearer
  EXPECT_EQ(cv::countNonZero(filled != expected), 0) << filled;

  const cv::Mat1f disparity = (cv::Mat1f(1, 7) << 0, 5, 0, 0, 9, 0, 0);
  const cv::Mat1f filled_d = fillLikeDevkit(disparity, MapKind::kDisparity);
  const cv::Mat1f expected_d = (cv::Mat1f(1, 7) << 5, 5, 9, 9, 9, 9, 9);  // max disparity
  EXPECT_EQ(cv::countNonZero(filled_d != expected_d), 0) << filled_d;
}

TEST(FillLikeDevkit, ColumnsAreExtendedUpAndDownButAnEmptyMiddleRowStaysEmpty) {
  // Rows 0, 2 and 4 are empty; rows 1 and 3 have one estimate each.
  cv::Mat1f depth(5, 3, 0.f);
  depth(1, 1) = 4.f;
  depth(3, 0) = 7.f;
  const cv::Mat1f filled = fillLikeDevkit(depth, MapKind::kDepth);
  const cv::Mat1f expected = (cv::Mat1f(5, 3) << 4, 4, 4,  //
                              4, 4, 4,                     //
                              0, 0, 0,                     // between two filled rows: as devkit
                              7, 7, 7,                     //
                              7, 7, 7);
  EXPECT_EQ(cv::countNonZero(filled != expected), 0) << filled;
}

TEST(FillLikeDevkit, InvalidValuesCountAsEmptyAndValidOnesAreKept) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const cv::Mat1f map = (cv::Mat1f(2, 4) << 2, nan, -1, 3, 0, 0, 0, 0);
  const cv::Mat1f filled = fillLikeDevkit(map, MapKind::kDisparity);
  const cv::Mat1f expected = (cv::Mat1f(2, 4) << 2, 3, 3, 3, 2, 3, 3, 3);
  EXPECT_EQ(cv::countNonZero(filled != expected), 0) << filled;
  EXPECT_EQ(cv::countNonZero(fillLikeDevkit(cv::Mat1f(3, 3, 0.f), MapKind::kDepth)), 0);
}

TEST(FillLikeDevkit, GapNextToTheBorderIsExtendedNotInterpolated) {
  // u1 == 0: the devkit skips the gap rule; left extrapolation copies the first estimate.
  const cv::Mat1f depth = (cv::Mat1f(1, 4) << 0, 0, 8, 3);
  const cv::Mat1f filled = fillLikeDevkit(depth, MapKind::kDepth);
  const cv::Mat1f expected = (cv::Mat1f(1, 4) << 8, 8, 8, 3);
  EXPECT_EQ(cv::countNonZero(filled != expected), 0) << filled;
}

}  // namespace
}  // namespace lidar_stereo_fusion
