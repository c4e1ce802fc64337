// Disparity <-> depth and the coloured cloud on hand-computed examples.
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

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

// The organised cloud (points2) on a grid: every pixel with depth is the same point, to the bit,
// as the unorganised cloud's; pixels without depth are NaN and keep their colour; the packed form
// holds the same bytes. BGR and grey, strides that do and do not divide the size.
TEST(OrganizedCloud, EqualsTheUnorganisedCloudOnTheGridWithNanElsewhere) {
  cv::Mat1f z(7, 9, 0.f);
  cv::Mat3b bgr(7, 9);
  for (int y = 0; y < z.rows; ++y) {
    for (int x = 0; x < z.cols; ++x) {
      if ((x * 3 + y) % 4 != 0) z(y, x) = 0.37f * static_cast<float>(1 + x + 2 * y);
      bgr(y, x) = cv::Vec3b(static_cast<uint8_t>(x), static_cast<uint8_t>(10 + y),
                            static_cast<uint8_t>(20 + x + y));
    }
  }
  z(3, 4) = std::numeric_limits<float>::quiet_NaN();
  cv::Mat1b grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  for (const cv::Mat& image : {cv::Mat(bgr), cv::Mat(grey)}) {
    for (const int stride : {1, 2, 3}) {
      SCOPED_TRACE("channels " + std::to_string(image.channels()) + ", stride " +
                   std::to_string(stride));
      const OrganizedCloud grid = makeOrganizedCloud(z, image, camera(9, 7), stride);
      const std::vector<ColoredPoint> points = makeColoredCloud(z, image, camera(9, 7), stride);
      std::vector<uint8_t> packed(grid.points.size() * kPackedPointBytes, 0xAB);
      EXPECT_FALSE(packOrganizedCloud(z, image, camera(9, 7), stride, packed.data()));
      ASSERT_EQ(grid.width, (9 + stride - 1) / stride);
      ASSERT_EQ(grid.height, (7 + stride - 1) / stride);
      ASSERT_EQ(grid.points.size(), static_cast<size_t>(grid.width * grid.height));
      size_t next = 0;
      for (int v = 0; v < grid.height; ++v) {
        for (int u = 0; u < grid.width; ++u) {
          const ColoredPoint& p = grid.points[v * grid.width + u];
          const int x = u * stride, y = v * stride;
          // The packed point: the same floats (NaN too, to the bit) and b, g, r, 0.
          const uint8_t* packed_point = packed.data() + (v * grid.width + u) * kPackedPointBytes;
          EXPECT_EQ(std::memcmp(packed_point, &p, 3 * sizeof(float)), 0) << x << ", " << y;
          EXPECT_EQ(packed_point[12], p.b);
          EXPECT_EQ(packed_point[13], p.g);
          EXPECT_EQ(packed_point[14], p.r);
          EXPECT_EQ(packed_point[15], 0);
          const bool has = std::isfinite(z(y, x)) && z(y, x) > 0.f;
          const uint8_t expected_b = image.channels() == 3 ? bgr(y, x)[0] : grey(y, x);
          const uint8_t expected_r = image.channels() == 3 ? bgr(y, x)[2] : grey(y, x);
          EXPECT_EQ(p.b, expected_b) << x << ", " << y;
          EXPECT_EQ(p.r, expected_r) << x << ", " << y;
          if (!has) {
            EXPECT_TRUE(std::isnan(p.x) && std::isnan(p.y) && std::isnan(p.z)) << x << ", " << y;
            continue;
          }
          ASSERT_LT(next, points.size());
          const ColoredPoint& q = points[next++];
          EXPECT_EQ(p.x, q.x);
          EXPECT_EQ(p.y, q.y);
          EXPECT_EQ(p.z, q.z);
          EXPECT_EQ(p.g, q.g);
        }
      }
      EXPECT_EQ(next, points.size());
    }
  }
}

}  // namespace
}  // namespace lidar_stereo_fusion
