// Message conversions without a ROS master, the outputs: depth with NaN for no value, the
// disparity image as stereo_image_proc's, the coloured cloud packed as PCL's, the organised cloud.
// The same binary (test_ros_unit) holds the images (test_conversions_images.cpp) and the clouds
// (test_conversions_clouds.cpp).
#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include <sensor_msgs/point_cloud2_iterator.h>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/ros/conversions.h"

namespace lsf = lidar_stereo_fusion;
namespace conv = lidar_stereo_fusion::conversions;

// --- outputs -------------------------------------------------------------------------------------
TEST(Conversions, DepthHasNanWhereEmptyOrTooFar) {
  cv::Mat1f depth(2, 3, 0.f);
  depth(0, 1) = 5.f;
  depth(1, 2) = 50.f;
  std_msgs::Header header;
  header.frame_id = "cam";
  const auto msg = conv::depthToMsg(depth, header, 40.0);
  EXPECT_EQ(msg->encoding, "32FC1");
  EXPECT_EQ(msg->step, 12u);
  const float* d = reinterpret_cast<const float*>(msg->data.data());
  EXPECT_TRUE(std::isnan(d[0]));
  EXPECT_FLOAT_EQ(d[1], 5.f);
  EXPECT_TRUE(std::isnan(d[5])) << "beyond max_depth";
}

TEST(Conversions, DisparityImageLikeStereoImageProc) {
  cv::Mat1f disparity(10, 20, 0.f);
  disparity(3, 4) = 2.5f;
  disparity(7, 15) = 191.f;
  disparity(1, 1) = 0.6f;    // below the search range: no value
  disparity(8, 18) = 250.f;  // above: no value
  lsf::StereoCamera camera;
  camera.fx = 500;
  camera.baseline = 0.3;
  std_msgs::Header header;
  const auto msg = conv::disparityToMsg(disparity, header, camera, 1.0, 192.0);
  EXPECT_FLOAT_EQ(msg->f, 500.f);
  EXPECT_FLOAT_EQ(msg->T, 0.3f);
  // The configured search range (issue 10), not this frame's values.
  EXPECT_FLOAT_EQ(msg->min_disparity, 1.f);
  EXPECT_FLOAT_EQ(msg->max_disparity, 192.f);
  const float* d = reinterpret_cast<const float*>(msg->image.data.data());
  EXPECT_EQ(d[1 * 20 + 1], 0.f);
  EXPECT_EQ(d[8 * 20 + 18], 0.f);
  EXPECT_EQ(d[3 * 20 + 4], 2.5f);
  EXPECT_GT(msg->min_disparity, 0.f) << "0 (no value) must be below min_disparity";
  EXPECT_EQ(msg->valid_window.x_offset, 4u);
  EXPECT_EQ(msg->valid_window.y_offset, 3u);
  EXPECT_EQ(msg->valid_window.width, 12u);
  EXPECT_EQ(msg->valid_window.height, 5u);
  EXPECT_EQ(msg->image.encoding, "32FC1");
}

TEST(Conversions, ColouredCloudPacksRgbLikePcl) {
  lsf::StereoCamera camera;
  camera.fx = camera.fy = 100;
  camera.cx = 2;
  camera.cy = 1;
  camera.baseline = 0.5;
  camera.width = camera.height = 1;
  const cv::Mat1f depth(1, 1, 3.f);
  const cv::Mat3b image(1, 1, cv::Vec3b(50, 100, 200));  // B, G, R
  const auto msg = conv::organizedCloudToMsg(depth, image, camera, 1, std_msgs::Header());
  EXPECT_TRUE(msg->is_dense);
  sensor_msgs::PointCloud2ConstIterator<uint8_t> r(*msg, "r"), g(*msg, "g"), b(*msg, "b");
  EXPECT_EQ(*r, 200);
  EXPECT_EQ(*g, 100);
  EXPECT_EQ(*b, 50);
  sensor_msgs::PointCloud2ConstIterator<float> x(*msg, "x"), y(*msg, "y"), z(*msg, "z");
  EXPECT_FLOAT_EQ(*x, -2 * 3.f / 100);
  EXPECT_FLOAT_EQ(*y, -1 * 3.f / 100);
  EXPECT_FLOAT_EQ(*z, 3.f);
  EXPECT_THROW(conv::organizedCloudToMsg(depth, image, camera, 0, std_msgs::Header()),
               std::invalid_argument);
}

TEST(Conversions, OrganisedCloudKeepsTheGridWithNanForNoValue) {
  lsf::StereoCamera camera;
  camera.fx = camera.fy = 100;
  camera.cx = 1.5;
  camera.cy = 1;
  camera.baseline = 0.5;
  camera.width = 4;
  camera.height = 3;
  cv::Mat1f depth(3, 4, 0.f);
  depth(2, 3) = 10.f;
  const cv::Mat3b image(3, 4, cv::Vec3b(1, 2, 3));
  const auto msg = conv::organizedCloudToMsg(depth, image, camera, 1, std_msgs::Header());
  EXPECT_EQ(msg->height, 3u);
  EXPECT_EQ(msg->width, 4u);
  EXPECT_EQ(msg->row_step, 4u * msg->point_step);
  EXPECT_FALSE(msg->is_dense);
  sensor_msgs::PointCloud2ConstIterator<float> z(*msg, "z");
  for (int i = 0; i < 12; ++i, ++z) {
    if (i == 2 * 4 + 3) {
      EXPECT_FLOAT_EQ(*z, 10.f);
    } else {
      EXPECT_TRUE(std::isnan(*z)) << i;
    }
  }
  const auto strided = conv::organizedCloudToMsg(depth, image, camera, 2, std_msgs::Header());
  EXPECT_EQ(strided->width, 2u);
  EXPECT_EQ(strided->height, 2u);
  EXPECT_EQ(strided->data.size(), 4u * strided->point_step);
}
