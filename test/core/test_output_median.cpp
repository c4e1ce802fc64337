// The output median (core/output_median.h) on small maps with exact answers: speckles and lines
// narrower than the window go, wider structures stay, empty pixels stay empty and do not count,
// the border is replicated; the parameter takes 0, 3 or 5 only. The LiDAR's points the output
// agrees with keep their value (medianKeepingMeasured), and which points count as measured.
#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/output_median.h"
#include "lidar_stereo_fusion/core/pipeline.h"

namespace lidar_stereo_fusion {
namespace {

cv::Mat1f flat(float value = 10.f) { return cv::Mat1f(9, 9, value); }

/// Number of pixels of `m` equal to `value`.
int countOf(const cv::Mat1f& m, float value) { return cv::countNonZero(m == value); }

TEST(OutputMedian, ASpeckleGoesAndTheRestIsUntouched) {
  cv::Mat1f d = flat();
  d(4, 4) = 20.f;
  d(0, 0) = 30.f;  // in the corner: replicated border, 4 of 9 samples are it
  for (int size : {3, 5}) {
    const cv::Mat1f out = medianOfValues(d, size);
    EXPECT_EQ(countOf(out, 10.f), 81) << size;
  }
}

TEST(OutputMedian, LinesNarrowerThanTheWindowGo) {
  for (int width : {1, 2, 3}) {
    cv::Mat1f d = flat();
    d.colRange(3, 3 + width).setTo(20.f);  // a vertical bar `width` columns wide
    const cv::Mat1f three = medianOfValues(d, 3);
    const cv::Mat1f five = medianOfValues(d, 5);
    EXPECT_EQ(countOf(three, 20.f), width == 1 ? 0 : 9 * width) << width;  // 3x3: 1 px goes
    EXPECT_EQ(countOf(five, 20.f), width < 3 ? 0 : 9 * width) << width;    // 5x5: 1 and 2 px go
  }
}

TEST(OutputMedian, EmptyPixelsStayEmptyAndDoNotCount) {
  cv::Mat1f d = cv::Mat1f::zeros(9, 9);
  d(cv::Rect(0, 0, 2, 2)).setTo(10.f);  // a 2x2 block of values in a corner, all else empty
  d(cv::Rect(5, 5, 3, 3)).setTo(12.f);  // a 3x3 block ...
  d(6, 6) = 40.f;                       // ... with a speckle in its middle
  const cv::Mat1f out = medianOfValues(d, 3);
  // cv::medianBlur would give the 2x2 block 0 (5 of its 9 samples are empty) and the speckle's
  // neighbours 0 too; here every value keeps a value and the empty pixels stay empty.
  EXPECT_EQ(countOf(out, 10.f), 4);
  EXPECT_EQ(countOf(out, 12.f), 9);  // the speckle among 8 values of 12 takes 12
  EXPECT_EQ(countOf(out, 0.f), 81 - 13);
  // An even count takes the lower middle: 2 values of 10 and 2 of 14 beside empty pixels.
  cv::Mat1f pair = cv::Mat1f::zeros(5, 5);
  pair(0, 0) = pair(0, 1) = 10.f;
  pair(1, 0) = pair(1, 1) = 14.f;
  EXPECT_EQ(medianOfValues(pair, 3)(0, 0), 10.f);
}

// A pole one pixel wide that the LiDAR measured on two rows (and the matcher kept): the plain
// median erases it, the median that keeps measured points keeps those two pixels exactly and
// removes the rest of the column as before; a measured point the output disagrees with by more
// than the tolerance is filtered like any pixel.
TEST(OutputMedian, MeasuredPointsTheOutputAgreesWithStay) {
  cv::Mat1f d = flat();
  d.col(4).setTo(20.f);
  cv::Mat1f measured = cv::Mat1f::zeros(9, 9);
  measured(2, 4) = 20.f;
  measured(6, 4) = 20.2f;  // within 0.5 px of the output's 20
  measured(7, 4) = 21.f;   // 1 px off: not confirmed by the output
  EXPECT_EQ(countOf(medianOfValues(d, 3), 20.f), 0);
  const cv::Mat1f out = medianKeepingMeasured(d, 3, measured, measured, 0.5f);
  EXPECT_EQ(countOf(out, 20.f), 2);
  EXPECT_EQ(out(2, 4), 20.f);
  EXPECT_EQ(out(6, 4), 20.f);  // the output's value, not the point's
  EXPECT_EQ(countOf(out, 10.f), 79);
  // with no tolerance only the exact point stays; 5x5 the same way
  EXPECT_EQ(countOf(medianKeepingMeasured(d, 3, measured, measured, 0.f), 20.f), 1);
  EXPECT_EQ(countOf(medianKeepingMeasured(d, 5, measured, measured, 0.5f), 20.f), 2);
  // an empty output pixel stays empty whatever was measured there
  d(2, 4) = 0.f;
  EXPECT_EQ(medianKeepingMeasured(d, 3, measured, measured, 0.5f)(2, 4), 0.f);
  EXPECT_THROW(medianKeepingMeasured(d, 3, cv::Mat1f::zeros(9, 8), measured, 0.5f),
               std::invalid_argument);
  EXPECT_THROW(medianKeepingMeasured(d, 3, measured, cv::Mat1f::zeros(8, 9), 0.5f),
               std::invalid_argument);
  EXPECT_THROW(medianKeepingMeasured(d, 3, measured, measured, -1.f), std::invalid_argument);
  EXPECT_THROW(medianKeepingMeasured(d, 3, measured, measured, NAN), std::invalid_argument);
}

// Measured: a projected point that the scan lines after Algorithm 1 still hold with its value;
// not a point Algorithm 1 removed (0 there), nor one a nearer line crosses (another value), nor a
// pixel the line completion filled between points.
TEST(OutputMedian, MeasuredPointsAreTheProjectionsThatTheScanLinesKeep) {
  cv::Mat1f sparse = cv::Mat1f::zeros(3, 6), lines = cv::Mat1f::zeros(3, 6);
  sparse(1, 0) = 5.f;  // kept
  lines(1, 0) = 5.f;
  lines(1, 1) = 5.5f;  // completed between points: not measured
  sparse(1, 2) = 6.f;  // kept
  lines(1, 2) = 6.f;
  sparse(1, 3) = 7.f;  // removed by Algorithm 1
  sparse(1, 4) = 8.f;  // crossed by a nearer line
  lines(1, 4) = 9.f;
  const cv::Mat1f m = measuredPoints(sparse, lines);
  const cv::Mat1f expected =
      (cv::Mat1f(3, 6) << 0, 0, 0, 0, 0, 0, 5, 0, 6, 0, 0, 0, 0, 0, 0, 0, 0, 0);
  EXPECT_EQ(cv::countNonZero(m != expected), 0) << m;
  EXPECT_THROW(measuredPoints(sparse, cv::Mat1f::zeros(3, 5)), std::invalid_argument);
  // the median keeps exactly these: a map of speckles, each pixel of the projection's value
  const cv::Mat1f speckles = cv::max(sparse, lines);
  const cv::Mat1f out = medianKeepingMeasured(speckles, 3, sparse, lines, 0.f);
  EXPECT_EQ(out(1, 0), 5.f);
  EXPECT_EQ(out(1, 2), 6.f);
  EXPECT_EQ(out(1, 1), medianOfValues(speckles, 3)(1, 1));
  EXPECT_EQ(out(1, 4), medianOfValues(speckles, 3)(1, 4));
}

TEST(OutputMedian, OnlySizesThreeAndFive) {
  EXPECT_THROW(medianOfValues(flat(), 4), std::invalid_argument);
  EXPECT_THROW(medianOfValues(flat(), 7), std::invalid_argument);
  EXPECT_THROW(medianOfValues(cv::Mat1f(), 3), std::invalid_argument);
  FusionParams params;
  for (int size : {0, 3, 5}) {
    params.patchmatch.output_median = size;
    EXPECT_NO_THROW(params.validate()) << size;
  }
  params.patchmatch.output_median = 4;
  try {
    params.validate();
    ADD_FAILURE() << "output_median 4 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("output_median must be 0, 3 or 5"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace lidar_stereo_fusion
