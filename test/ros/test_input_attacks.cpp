// Regression tests of issue 9's crashes in the ROS conversions (no ROS master needed): each of
// these messages once took down the nodelet manager. Now each is rejected with a reason.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include <sensor_msgs/image_encodings.h>
#include <boost/make_shared.hpp>

#include "../../fuzz/fuzz_messages.h"
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

// Issue 25, point 1: a coordinate of an integer type was read as metres (a UINT8 'x' put 95,129
// KITTI points in front of the camera instead of 55,058); a field holding several values was
// read as its first. Each is refused, naming the field, its type or its count.
TEST(InputAttacks, CoordinatesOfIntegerTypesAndFieldsWithSeveralValuesAreRefused) {
  for (const uint8_t type : {PointField::INT8, PointField::UINT8, PointField::INT16,
                             PointField::UINT16, PointField::INT32, PointField::UINT32}) {
    for (int axis = 0; axis < 3; ++axis) {
      auto msg = cloudWithField("intensity", 12);
      msg.fields[axis].datatype = type;
      const std::string problem = conv::checkCloudLayout(msg);
      const std::string name = std::string("'") + "xyz"[axis] + "'";
      EXPECT_NE(problem.find(name), std::string::npos) << problem;
      EXPECT_NE(problem.find("FLOAT32 or FLOAT64"), std::string::npos) << problem;
      EXPECT_THROW(conv::cloudFromMsg(msg), conv::ConversionError);
    }
  }
  auto uint8_x = cloudWithField("intensity", 12);
  uint8_x.fields[0].datatype = PointField::UINT8;
  EXPECT_NE(conv::checkCloudLayout(uint8_x).find("UINT8"), std::string::npos);
  for (const std::string name : {"x", "intensity", "ring", "time"}) {
    auto msg = cloudWithField(name == "x" ? "intensity" : name, 12);
    for (auto& f : msg.fields) {
      if (f.name == name) f.count = 3;
    }
    const std::string problem = conv::checkCloudLayout(msg);
    EXPECT_NE(problem.find("'" + name + "' has count 3"), std::string::npos) << problem;
  }
  // A field the reader does not read may hold anything.
  auto other = cloudWithField("normal", 12);
  other.fields[3].count = 3;
  other.fields[3].datatype = PointField::UINT8;
  EXPECT_EQ(conv::checkCloudLayout(other), "");
  // Integer rings and intensities are exact and stay accepted.
  auto ring = cloudWithField("ring", 12);
  ring.fields[3].datatype = PointField::UINT16;
  EXPECT_EQ(conv::checkCloudLayout(ring), "");
}

// Issue 25, point 7: finite but absurd coordinates (1e38) and NaN / inf are dropped and counted.
TEST(InputAttacks, AbsurdAndNonFinitePointsAreDroppedAndCounted) {
  auto msg = cloudWithField("intensity", 12);
  msg.width = 4;
  msg.row_step = 64;
  msg.data.assign(64, 0);
  const auto put = [&](int point, int field, float v) {
    std::memcpy(&msg.data[point * 16 + field * 4], &v, 4);
  };
  put(0, 0, 1e38f);
  put(1, 2, std::numeric_limits<float>::infinity());
  put(2, 1, std::numeric_limits<float>::quiet_NaN());
  put(3, 0, 5.f);
  const conv::CloudConversion out = conv::cloudFromMsg(msg);
  EXPECT_EQ(out.cloud.size(), 1u);
  EXPECT_EQ(out.implausible, 1);
  EXPECT_EQ(out.non_finite, 2);
}

// Found by fuzz_pointcloud2: a cloud with width 0 and height > 0 stepped a null data pointer.
TEST(InputAttacks, EmptyCloudWithRowsAndNoDataIsEmpty) {
  auto msg = cloudWithField("intensity", 12);
  msg.width = 0;
  msg.height = 5;
  msg.row_step = 220;
  msg.data.clear();
  EXPECT_EQ(conv::checkCloudLayout(msg), "");
  EXPECT_TRUE(conv::cloudFromMsg(msg).cloud.empty());
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

sensor_msgs::CameraInfo infoWithP(double fx, double tx) {
  sensor_msgs::CameraInfo c;
  c.width = 64;
  c.height = 32;
  c.P = {fx, 0, 31.5, tx, 0, fx, 15.5, 0, 0, 0, 1, 0};
  return c;
}

// Point 10: fx NaN was reported as "no baseline"; point 5: a right P[3] in millimetres (1000x the
// baseline) was accepted.
TEST(InputAttacks, NonFiniteFocalLengthAndMillimetreBaselineAreNamed) {
  const auto nan = std::numeric_limits<double>::quiet_NaN();
  try {
    conv::stereoCameraFromInfo(infoWithP(nan, 0), infoWithP(nan, -386.0));
    ADD_FAILURE() << "fx NaN accepted";
  } catch (const conv::ConversionError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("left camera_info: P[0]"), std::string::npos) << what;
    EXPECT_EQ(what.find("baseline"), std::string::npos) << what;
  }
  EXPECT_NO_THROW(conv::stereoCameraFromInfo(infoWithP(721.5, 0), infoWithP(721.5, -387.6)));
  try {
    conv::stereoCameraFromInfo(infoWithP(721.5, 0), infoWithP(721.5, -387570.0));
    ADD_FAILURE() << "a 537 m baseline accepted";
  } catch (const conv::ConversionError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("millimetres"), std::string::npos) << what;
    EXPECT_NE(what.find("537"), std::string::npos) << what;
  }
}

// Seed corpora of fuzz/fuzz_pointcloud2 and fuzz/fuzz_image (scripts/run_fuzz.sh): valid messages
// of every layout the tests use and the messages that once crashed, in the fuzz targets' byte
// layout. Each decodes back to the message it came from.
TEST(InputAttacks, WritesTheFuzzSeedCorpora) {
  namespace fs = std::filesystem;
  const auto write = [](const std::string& target, const std::string& name,
                        const std::vector<uint8_t>& bytes) {
    const fs::path dir = fs::path(LSF_BINARY_DIR) / "fuzz_seeds" / target;
    fs::create_directories(dir);
    std::ofstream(dir / name, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
  };
  lidar_stereo_fusion::LidarCloud cloud(40);
  for (int i = 0; i < 40; ++i) {
    cloud[i].x = 5.f + 0.1f * i;
    cloud[i].y = -1.f + 0.05f * i;
    cloud[i].z = 0.2f * (i % 4);
    cloud[i].ring = i % 4;
  }
  std_msgs::Header header;
  header.frame_id = "velodyne";
  const sensor_msgs::PointCloud2 velodyne = conv::cloudToMsg(cloud, header);
  const std::vector<uint8_t> bytes = lsf_fuzz::encodeCloud(velodyne);
  const sensor_msgs::PointCloud2 back = lsf_fuzz::decodeCloud(bytes.data(), bytes.size());
  EXPECT_EQ(conv::cloudFromMsg(back).cloud.size(), 40u);
  write("pointcloud2", "velodyne_layout", bytes);
  write("pointcloud2", "offset_near_2_32",
        lsf_fuzz::encodeCloud(cloudWithField("intensity", 4294967292u)));
  sensor_msgs::PointCloud2 organised = velodyne;
  organised.height = 4;
  organised.width = 10;
  organised.row_step = organised.point_step * 10;
  write("pointcloud2", "organised", lsf_fuzz::encodeCloud(organised));
  sensor_msgs::PointCloud2 uint8_x = velodyne;  // issue 25, point 1
  uint8_x.fields[0].datatype = PointField::UINT8;
  write("pointcloud2", "uint8_x", lsf_fuzz::encodeCloud(uint8_x));
  sensor_msgs::PointCloud2 count3 = velodyne;
  count3.fields[3].count = 3;
  write("pointcloud2", "intensity_count_3", lsf_fuzz::encodeCloud(count3));

  for (const std::string encoding : {"bgra8", "bgr8", "mono8", "rgb8"}) {
    sensor_msgs::Image image;
    image.encoding = encoding;
    image.width = 8;
    image.height = 4;
    image.step = 8 * sensor_msgs::image_encodings::numChannels(encoding);
    image.data.assign(image.step * image.height, 77);
    const std::vector<uint8_t> image_bytes = lsf_fuzz::encodeImage(image);
    const auto decoded = boost::make_shared<sensor_msgs::Image>(
        lsf_fuzz::decodeImage(image_bytes.data(), image_bytes.size()));
    EXPECT_EQ(conv::imageToCore(decoded).cols, 8) << encoding;
    write("image", encoding, image_bytes);
  }
  sensor_msgs::Image wide;
  wide.encoding = "bgra8";
  wide.width = 1u << 30;
  wide.height = 1;
  wide.step = 1;
  wide.data.assign(16, 0);
  write("image", "width_2_30", lsf_fuzz::encodeImage(wide));
}
