// Message conversions without a ROS master, the sweeps: the Velodyne layout with any numeric field
// types, clouds without ring or with NaN, organised clouds with row padding, malformed clouds and
// the round trip. The same binary (test_ros_unit) holds the images (test_conversions_images.cpp)
// and the outputs (test_conversions_outputs.cpp).
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/ros/conversions.h"

namespace lsf = lidar_stereo_fusion;
namespace conv = lidar_stereo_fusion::conversions;
using sensor_msgs::PointField;

namespace {

/// A cloud with one point per entry of `xyz`, fields laid out as given.
struct FieldSpec {
  std::string name;
  uint8_t datatype;
};
int sizeOf(uint8_t datatype) {
  switch (datatype) {
    case PointField::INT8:
    case PointField::UINT8:
      return 1;
    case PointField::INT16:
    case PointField::UINT16:
      return 2;
    case PointField::FLOAT64:
      return 8;
    default:
      return 4;
  }
}
template <class T>
void put(uint8_t* p, double v) {
  const T t = static_cast<T>(v);
  std::memcpy(p, &t, sizeof(T));
}
void putValue(uint8_t* p, uint8_t datatype, double v) {
  switch (datatype) {
    case PointField::INT8:
      put<int8_t>(p, v);
      break;
    case PointField::UINT8:
      put<uint8_t>(p, v);
      break;
    case PointField::INT16:
      put<int16_t>(p, v);
      break;
    case PointField::UINT16:
      put<uint16_t>(p, v);
      break;
    case PointField::INT32:
      put<int32_t>(p, v);
      break;
    case PointField::UINT32:
      put<uint32_t>(p, v);
      break;
    case PointField::FLOAT32:
      put<float>(p, v);
      break;
    default:
      put<double>(p, v);
      break;
  }
}
sensor_msgs::PointCloud2 makeCloud(const std::vector<FieldSpec>& fields,
                                   const std::vector<std::vector<double>>& points,
                                   int padding = 3) {
  sensor_msgs::PointCloud2 msg;
  uint32_t offset = 0;
  for (const auto& f : fields) {
    PointField pf;
    pf.name = f.name;
    pf.datatype = f.datatype;
    pf.count = 1;
    pf.offset = offset;
    offset += sizeOf(f.datatype) + padding;  // odd padding: unaligned fields
    msg.fields.push_back(pf);
  }
  msg.point_step = offset;
  msg.height = 1;
  msg.width = points.size();
  msg.row_step = msg.point_step * msg.width;
  msg.data.assign(msg.row_step, 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t f = 0; f < fields.size(); ++f) {
      putValue(&msg.data[i * msg.point_step + msg.fields[f].offset], fields[f].datatype,
               points[i][f]);
    }
  }
  return msg;
}

}  // namespace

// --- clouds --------------------------------------------------------------------------------------
TEST(Conversions, VelodyneLayoutWithAnyNumericTypes) {
  const std::vector<uint8_t> ring_types = {PointField::UINT8, PointField::UINT16, PointField::INT32,
                                           PointField::FLOAT32, PointField::FLOAT64};
  const std::vector<uint8_t> time_types = {PointField::FLOAT32, PointField::FLOAT64,
                                           PointField::UINT32};
  for (const uint8_t xyz : {PointField::FLOAT32, PointField::FLOAT64}) {
    for (const uint8_t ring : ring_types) {
      for (const uint8_t time : time_types) {
        const auto msg = makeCloud({{"x", xyz},
                                    {"y", xyz},
                                    {"z", xyz},
                                    {"intensity", PointField::UINT8},
                                    {"ring", ring},
                                    {"time", time}},
                                   {{1.5, -2.25, 0.5, 200, 7, 3}, {10.0, 0.0, -1.0, 3, 0, 0}});
        // A time of 3 s (a whole number for the integer types) is plausible up to 10 s.
        const conv::CloudConversion out = conv::cloudFromMsg(msg, 10.0);
        ASSERT_EQ(out.cloud.size(), 2u);
        EXPECT_TRUE(out.has_ring);
        EXPECT_TRUE(out.has_time);
        EXPECT_FLOAT_EQ(out.cloud[0].x, 1.5f);
        EXPECT_FLOAT_EQ(out.cloud[0].y, -2.25f);
        EXPECT_FLOAT_EQ(out.cloud[0].z, 0.5f);
        EXPECT_FLOAT_EQ(out.cloud[0].intensity, 200.f);
        EXPECT_EQ(out.cloud[0].ring, 7);
        EXPECT_FLOAT_EQ(out.cloud[0].time, 3.f);
        EXPECT_EQ(out.cloud[1].ring, 0);
      }
    }
  }
}

TEST(Conversions, CloudWithoutRingAndWithNaN) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto msg =
      makeCloud({{"x", PointField::FLOAT32},
                 {"y", PointField::FLOAT32},
                 {"z", PointField::FLOAT32},
                 {"laser_id", PointField::UINT16}},
                {{1, 2, 3, 5}, {nan, 0, 0, 1}, {0, std::numeric_limits<double>::infinity(), 0, 1}});
  const conv::CloudConversion out = conv::cloudFromMsg(msg);
  EXPECT_FALSE(out.has_ring);
  EXPECT_FALSE(out.has_time);
  EXPECT_EQ(out.total_points, 3);
  EXPECT_EQ(out.non_finite, 2);
  ASSERT_EQ(out.cloud.size(), 1u);
  EXPECT_EQ(out.cloud[0].ring, -1);
}

TEST(Conversions, OrganisedCloudWithRowPadding) {
  auto msg = makeCloud(
      {{"x", PointField::FLOAT32}, {"y", PointField::FLOAT32}, {"z", PointField::FLOAT32}},
      {{1, 2, 3}, {4, 5, 6}, {7, 8, 9}, {10, 11, 12}}, 0);
  // Re-lay the 4 points as 2 rows of 2 with 8 bytes of padding at the end of each row.
  sensor_msgs::PointCloud2 organised = msg;
  organised.height = 2;
  organised.width = 2;
  organised.row_step = 2 * msg.point_step + 8;
  organised.data.assign(organised.row_step * 2, 0xff);
  for (int r = 0; r < 2; ++r) {
    std::memcpy(&organised.data[r * organised.row_step], &msg.data[r * 2 * msg.point_step],
                2 * msg.point_step);
  }
  const conv::CloudConversion out = conv::cloudFromMsg(organised);
  ASSERT_EQ(out.cloud.size(), 4u);
  EXPECT_FLOAT_EQ(out.cloud[3].z, 12.f);
}

TEST(Conversions, MalformedCloudsAreRejectedWithTheReason) {
  auto no_z = makeCloud({{"x", PointField::FLOAT32}, {"y", PointField::FLOAT32}}, {{1, 2}});
  EXPECT_NE(conv::checkCloudLayout(no_z).find("'z'"), std::string::npos);
  EXPECT_THROW(conv::cloudFromMsg(no_z), conv::ConversionError);

  auto ok = makeCloud(
      {{"x", PointField::FLOAT32}, {"y", PointField::FLOAT32}, {"z", PointField::FLOAT32}},
      {{1, 2, 3}, {4, 5, 6}});
  auto short_data = ok;
  short_data.data.resize(short_data.data.size() - 1);
  EXPECT_FALSE(conv::checkCloudLayout(short_data).empty());
  auto small_step = ok;
  small_step.point_step = 6;
  small_step.row_step = 12;
  EXPECT_FALSE(conv::checkCloudLayout(small_step).empty());
  auto big_endian = ok;
  big_endian.is_bigendian = true;
  EXPECT_FALSE(conv::checkCloudLayout(big_endian).empty());
  auto empty = ok;
  empty.width = 0;
  empty.row_step = 0;
  empty.data.clear();
  EXPECT_TRUE(conv::checkCloudLayout(empty).empty()) << "empty is well-formed (rejected later)";
  EXPECT_TRUE(conv::cloudFromMsg(empty).cloud.empty());
}

TEST(Conversions, CloudRoundTrip) {
  lsf::LidarCloud cloud(3);
  for (int i = 0; i < 3; ++i) {
    cloud[i].x = i;
    cloud[i].y = -i;
    cloud[i].z = 0.5f * i;
    cloud[i].intensity = 10.f * i;
    cloud[i].ring = i + 1;
    cloud[i].time = 0.01f * i;
  }
  std_msgs::Header header;
  header.frame_id = "velodyne";
  const conv::CloudConversion out = conv::cloudFromMsg(conv::cloudToMsg(cloud, header));
  ASSERT_EQ(out.cloud.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_FLOAT_EQ(out.cloud[i].y, -i);
    EXPECT_EQ(out.cloud[i].ring, i + 1);
    EXPECT_FLOAT_EQ(out.cloud[i].time, 0.01f * i);
  }
}
