// Disparity <-> depth and the coloured cloud on hand-computed examples.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/depth.h"

namespace lidar_stereo_fusion {
namespace {

/// fx * B = 50 px m.
StereoCamera camera(int width, int height) {
  StereoCamera c;
  c.fx = 100.0;
  c.fy = 50.0;
  c.cx = 1.0;
  c.cy = 2.0;
  c.baseline = 0.5;
  c.width = width;
  c.height = height;
  return c;
}

TEST(Depth, DisparityToDepthIsFxBOverDAndMarksInvalidWithZero) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const cv::Mat1f d = (cv::Mat1f(2, 3) << 10, 0, -1, nan, 0.5, inf);
  const cv::Mat1f z = disparityToDepth(d, camera(3, 2));
  EXPECT_FLOAT_EQ(z(0, 0), 5.f);
  EXPECT_EQ(z(0, 1), 0.f);
  EXPECT_EQ(z(0, 2), 0.f);
  EXPECT_EQ(z(1, 0), 0.f);
  EXPECT_FLOAT_EQ(z(1, 1), 100.f);
  EXPECT_EQ(z(1, 2), 0.f);
  const cv::Mat1f limited = disparityToDepth(d, camera(3, 2), 80.0);
  EXPECT_FLOAT_EQ(limited(0, 0), 5.f);
  EXPECT_EQ(limited(1, 1), 0.f);  // 100 m > 80 m
}

TEST(Depth, DepthToDisparityInvertsAndRoundTrips) {
  const cv::Mat1f z = (cv::Mat1f(1, 4) << 5, 0, -3, 12.5);
  const cv::Mat1f d = depthToDisparity(z, camera(4, 1));
  EXPECT_FLOAT_EQ(d(0, 0), 10.f);
  EXPECT_EQ(d(0, 1), 0.f);
  EXPECT_EQ(d(0, 2), 0.f);
  EXPECT_FLOAT_EQ(d(0, 3), 4.f);
  const cv::Mat1f back = disparityToDepth(d, camera(4, 1));
  EXPECT_FLOAT_EQ(back(0, 0), 5.f);
  EXPECT_FLOAT_EQ(back(0, 3), 12.5f);
}

TEST(Depth, BadInputIsAnError) {
  EXPECT_THROW(disparityToDepth(cv::Mat1f(2, 2, 1.f), camera(3, 2)), std::invalid_argument);
  EXPECT_THROW(disparityToDepth(cv::Mat1f(2, 3, 1.f), camera(3, 2), -1.0), std::invalid_argument);
  StereoCamera bad = camera(3, 2);
  bad.fx = 0;
  EXPECT_THROW(depthToDisparity(cv::Mat1f(2, 3, 1.f), bad), std::invalid_argument);
}

TEST(ColoredCloud, BackProjectsWithIntrinsicsAndTakesRgbFromBgr) {
  cv::Mat1f z(3, 4, 0.f);
  z(0, 0) = 2.f;
  z(2, 3) = 4.f;
  z(1, 2) = 1.f;
  cv::Mat image(3, 4, CV_8UC3, cv::Scalar(0, 0, 0));
  image.at<cv::Vec3b>(2, 3) = cv::Vec3b(10, 20, 30);  // B, G, R
  const auto cloud = makeColoredCloud(z, image, camera(4, 3));
  ASSERT_EQ(cloud.size(), 3u);
  EXPECT_FLOAT_EQ(cloud[0].x, (0 - 1.0f) * 2 / 100);
  EXPECT_FLOAT_EQ(cloud[0].y, (0 - 2.0f) * 2 / 50);
  EXPECT_FLOAT_EQ(cloud[0].z, 2.f);
  EXPECT_FLOAT_EQ(cloud[1].x, (2 - 1.0f) * 1 / 100);  // row-major: (1, 2) before (2, 3)
  EXPECT_FLOAT_EQ(cloud[1].y, (1 - 2.0f) * 1 / 50);
  EXPECT_FLOAT_EQ(cloud[2].x, (3 - 1.0f) * 4 / 100);
  EXPECT_FLOAT_EQ(cloud[2].y, (2 - 2.0f) * 4 / 50);
  EXPECT_EQ(cloud[2].r, 30);
  EXPECT_EQ(cloud[2].g, 20);
  EXPECT_EQ(cloud[2].b, 10);
}

TEST(ColoredCloud, GreyImagesStrideAndBadInput) {
  const cv::Mat1f z(4, 4, 3.f);
  const cv::Mat1b grey(4, 4, uint8_t{77});
  const auto all = makeColoredCloud(z, grey, camera(4, 4));
  EXPECT_EQ(all.size(), 16u);
  EXPECT_EQ(all[5].r, 77);
  EXPECT_EQ(all[5].b, 77);
  const auto strided = makeColoredCloud(z, grey, camera(4, 4), 2);
  ASSERT_EQ(strided.size(), 4u);  // (0,0) (0,2) (2,0) (2,2)
  EXPECT_FLOAT_EQ(strided[3].x, (2 - 1.0f) * 3 / 100);
  EXPECT_FLOAT_EQ(strided[3].y, (2 - 2.0f) * 3 / 50);
  EXPECT_THROW(makeColoredCloud(z, grey, camera(4, 4), 0), std::invalid_argument);
  EXPECT_THROW(makeColoredCloud(z, cv::Mat1b(3, 4), camera(4, 4)), std::invalid_argument);
  EXPECT_THROW(makeColoredCloud(z, cv::Mat1f(4, 4), camera(4, 4)), std::invalid_argument);
}

}  // namespace
}  // namespace lidar_stereo_fusion
