// checkTopBand (eval/top_band_check.h) on small synthetic frames with exact counts.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "eval_test_scenes.h"
#include "lidar_stereo_fusion/eval/top_band_check.h"

namespace lsf = lidar_stereo_fusion;

namespace {

using lsf::test::camera;
using lsf::test::shiftedTexture;

}  // namespace

TEST(TopBand, CountsNearPlanesAboveFarTopsAndExcusesWhatTheLidarOrImagesShow) {
  const int w = 40, h = 30;
  const lsf::StereoCamera cam = camera(w, h);
  cv::Mat1b left, right;
  shiftedTexture(w, h, 2, left, right);  // the images match at 2 px (25 m) everywhere
  cv::Mat1f fed = cv::Mat1f::zeros(h, w), out = cv::Mat1f::zeros(h, w);
  for (int x = 0; x < w; ++x) fed(20, x) = 2.f;  // the top line: 25 m
  out.setTo(2.f);
  // Columns 10..14: a band of 5 px (10 m < 0.6 x 25 m) two rows above the top line.
  for (int x = 10; x < 15; ++x) out(18, x) = 5.f;
  lsf::TopBandReport r = lsf::checkTopBand(fed, out, left, right, cam);
  EXPECT_EQ(r.columns, w);
  EXPECT_EQ(r.banded, 5);
  EXPECT_EQ(r.excused, 0);
  EXPECT_DOUBLE_EQ(r.bandedShare(), 5.0 / w);

  // A pole at 10 m beside columns 10..14 (column 16, rising to row 15): the LiDAR shows it,
  // within 3 columns of 13 and 14 only.
  for (int y = 15; y <= 20; ++y) fed(y, 16) = 5.f;
  r = lsf::checkTopBand(fed, out, left, right, cam);
  EXPECT_EQ(r.excused, 2);
  EXPECT_EQ(r.banded, 3);

  // The images: with the right image shifted by 5 px the near disparity matches, the far not.
  shiftedTexture(w, h, 5, left, right);
  r = lsf::checkTopBand(fed, out, left, right, cam);
  EXPECT_EQ(r.banded, 0);
  EXPECT_EQ(r.excused, 5);
}

TEST(TopBand, IgnoresNearTopsAndRejectsBadInput) {
  const int w = 10, h = 10;
  cv::Mat1b left(h, w, uchar(0)), right(h, w, uchar(0));
  cv::Mat1f fed = cv::Mat1f::zeros(h, w), out(h, w, 30.f);
  for (int x = 0; x < w; ++x) fed(5, x) = 10.f;  // 5 m: nearer than min_depth
  const lsf::TopBandReport r = lsf::checkTopBand(fed, out, left, right, camera(w, h));
  EXPECT_EQ(r.columns, 0);
  EXPECT_EQ(r.bandedShare(), 0.0);
  EXPECT_THROW(lsf::checkTopBand(cv::Mat1f(), out, left, right, camera(w, h)),
               std::invalid_argument);
  EXPECT_THROW(lsf::checkTopBand(fed, cv::Mat1f::zeros(h, w + 1), left, right, camera(w, h)),
               std::invalid_argument);
}
