// Regression tests of issue 9's crashes in the ROS conversions (no ROS master needed): each of
// these messages once took down the nodelet manager. Now each is rejected with a reason.
#include <cstdint>
#include <string>

#include <gtest/gtest.h>

#include <sensor_msgs/image_encodings.h>
#include <boost/make_shared.hpp>

#include "lidar_stereo_fusion/ros/conversions.h"

namespace conv = lidar_stereo_fusion::conversions;
using sensor_msgs::PointField;

namespace {

/// A valid 2-point cloud with float32 x, y, z and a 16-byte point_step.
sensor_msgs::PointCloud2 cloudWithField(const std::string& name, uint32_t offset) {
  sensor_msgs::PointCloud2 msg;
  const char* names[] = {"x", "y", "z"};
  for (uint32_t i = 0; i < 3; ++i) {
    PointField f;
    f.name = names[i];
    f.offset = 4 * i;
    f.datatype = PointField::FLOAT32;
    f.count = 1;
    msg.fields.push_back(f);
  }
  PointField extra;
  extra.name = name;
  extra.offset = offset;
  extra.datatype = PointField::FLOAT32;
  extra.count = 1;
  msg.fields.push_back(extra);
  msg.height = 1;
  msg.width = 2;
  msg.point_step = 16;
  msg.row_step = 32;
  msg.data.assign(32, 0);
  return msg;
}

}  // namespace

// Crash 1: offset 4294967292 + 4 wrapped to 0 in 32 bits, passed the check, and the read went
// 4 GiB past the buffer (SIGSEGV).
TEST(InputAttacks, FieldOffsetNearTwoToThe32IsRejected) {
  for (const std::string name : {"intensity", "ring", "time", "x_extra"}) {
    for (const uint32_t offset : {4294967292u, 4294967295u, 4294967280u, 13u}) {
      auto msg = cloudWithField(name, offset);
      const std::string problem = conv::checkCloudLayout(msg);
      EXPECT_NE(problem.find("does not fit in point_step"), std::string::npos)
          << name << " at " << offset << ": '" << problem << "'";
      EXPECT_THROW(conv::cloudFromMsg(msg), conv::ConversionError);
    }
  }
  // And the x field itself.
  auto msg = cloudWithField("intensity", 12);
  msg.fields[0].offset = 4294967292u;
  EXPECT_FALSE(conv::checkCloudLayout(msg).empty());
  EXPECT_THROW(conv::cloudFromMsg(msg), conv::ConversionError);
}

// Crash 2: width 2^30 bgra8, height 1, step 1: width * 4 wrapped to 0 in 32 bits, the check
// passed and the cv::Exception that followed was not caught (terminate).
TEST(InputAttacks, ImageWidthThatWrapsWidthTimesChannelsIsRejected) {
  for (const std::string encoding : {"bgra8", "rgba8", "rgb8", "bgr8", "mono8"}) {
    for (const uint32_t width : {1u << 30, (1u << 31) + 1u, 4294967295u}) {
      auto msg = boost::make_shared<sensor_msgs::Image>();
      msg->encoding = encoding;
      msg->width = width;
      msg->height = 1;
      msg->step = 1;
      msg->data.assign(16, 0);
      EXPECT_FALSE(conv::checkImage(*msg).empty()) << encoding << " width " << width;
      EXPECT_THROW(conv::imageToCore(msg), conv::ConversionError) << encoding << " " << width;
    }
  }
  // Height that does not fit in an int.
  auto tall = boost::make_shared<sensor_msgs::Image>();
  tall->encoding = "mono8";
  tall->width = 1;
  tall->height = 4294967295u;
  tall->step = 1;
  EXPECT_FALSE(conv::checkImage(*tall).empty());
  EXPECT_THROW(conv::imageToCore(tall), conv::ConversionError);
}
