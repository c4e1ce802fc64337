// The output median (core/output_median.h) on small maps with exact answers: speckles and lines
// narrower than the window go, wider structures stay, empty pixels stay empty and do not count,
// the border is replicated; the parameter takes 0, 3 or 5 only.
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
