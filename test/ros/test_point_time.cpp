// Per-point time of the common LiDAR drivers (conversions::PointTimeField): each layout gives the
// offset from the cloud's stamp exactly; implausible times are counted and not used; the real
// Luminar bag reads as one sweep of about 90 ms ending at its stamp. Also writes the fuzz seeds of
// these layouts (fuzz/fuzz_pointcloud2).
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "../../fuzz/fuzz_messages.h"
#include "../data/data_guard.h"
#include "lidar_stereo_fusion/ros/conversions.h"

namespace conv = lidar_stereo_fusion::conversions;
using sensor_msgs::PointField;

namespace {

/// Three points at x = 10, 20, 30 m with one or two time fields of the given types, the values
/// written as `values[point][field]`.
sensor_msgs::PointCloud2 timedCloud(const std::vector<std::pair<std::string, uint8_t>>& fields,
                                    const std::vector<std::vector<double>>& values,
                                    const ros::Time& stamp) {
  sensor_msgs::PointCloud2 msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = "lidar";
  uint32_t offset = 0;
  for (const char* name : {"x", "y", "z"}) {
    PointField f;
    f.name = name;
    f.offset = offset;
    f.datatype = PointField::FLOAT32;
    f.count = 1;
    msg.fields.push_back(f);
    offset += 4;
  }
  for (const auto& [name, type] : fields) {
    PointField f;
    f.name = name;
    f.offset = offset;
    f.datatype = type;
    f.count = 1;
    msg.fields.push_back(f);
    offset += 8;  // room for any type
  }
  msg.point_step = offset;
  msg.width = static_cast<uint32_t>(values.size());
  msg.height = 1;
  msg.row_step = msg.point_step * msg.width;
  msg.data.assign(msg.row_step, 0);
  for (size_t i = 0; i < values.size(); ++i) {
    uint8_t* p = msg.data.data() + i * msg.point_step;
    const float x = 10.f * static_cast<float>(i + 1), y = 0.f, z = 0.f;
    std::memcpy(p, &x, 4);
    std::memcpy(p + 4, &y, 4);
    std::memcpy(p + 8, &z, 4);
    for (size_t k = 0; k < fields.size(); ++k) {
      uint8_t* q = p + msg.fields[3 + k].offset;
      const double v = values[i][k];
      switch (fields[k].second) {
        case PointField::FLOAT32: {
          const float f = static_cast<float>(v);
          std::memcpy(q, &f, 4);
          break;
        }
        case PointField::FLOAT64:
          std::memcpy(q, &v, 8);
          break;
        case PointField::UINT32: {
          const uint32_t u = static_cast<uint32_t>(v);
          std::memcpy(q, &u, 4);
          break;
        }
        default:
          ADD_FAILURE() << "type not used here";
      }
    }
  }
  return msg;
}

const ros::Time kStamp(1317013000, 500000000);  // 2011-09-26, as KITTI 0009: x.5 s

std::vector<float> times(const conv::CloudConversion& c) {
  std::vector<float> t;
  for (const auto& p : c.cloud) t.push_back(p.time);
  return t;
}

TEST(PointTime, VelodyneTimeIsSecondsFromTheStamp) {
  const auto c = conv::cloudFromMsg(
      timedCloud({{"time", PointField::FLOAT32}}, {{-0.0625}, {0.0}, {0.03125}}, kStamp));
  EXPECT_EQ(c.time_field, conv::PointTimeField::kTime);
  EXPECT_TRUE(c.has_time);
  EXPECT_EQ(times(c), (std::vector<float>{-0.0625f, 0.f, 0.03125f}));
  EXPECT_EQ(c.bad_times, 0);
}

TEST(PointTime, OusterAndLivoxNanosecondsFromTheStamp) {
  for (const char* name : {"t", "offset_time"}) {
    const auto c = conv::cloudFromMsg(
        timedCloud({{name, PointField::UINT32}}, {{0.0}, {50000000.0}, {99000000.0}}, kStamp));
    EXPECT_STREQ(conv::pointTimeFieldName(c.time_field), name);
    ASSERT_EQ(c.cloud.size(), 3u);
    EXPECT_FLOAT_EQ(c.cloud[0].time, 0.f);
    EXPECT_FLOAT_EQ(c.cloud[1].time, 0.05f);
    EXPECT_FLOAT_EQ(c.cloud[2].time, 0.099f);
  }
}

TEST(PointTime, HesaiAbsoluteTimestamp) {
  const double s = kStamp.toSec();
  const auto c = conv::cloudFromMsg(
      timedCloud({{"timestamp", PointField::FLOAT64}}, {{s - 0.1}, {s - 0.05}, {s}}, kStamp));
  EXPECT_EQ(c.time_field, conv::PointTimeField::kTimestamp);
  ASSERT_EQ(c.cloud.size(), 3u);
  EXPECT_NEAR(c.cloud[0].time, -0.1, 1e-6);  // a double at 1.3e9 s keeps ~0.2 us
  EXPECT_NEAR(c.cloud[1].time, -0.05, 1e-6);
  EXPECT_NEAR(c.cloud[2].time, 0.0, 1e-6);
}

TEST(PointTime, LuminarSecondsAndNanosecondsExactly) {
  const auto msg = timedCloud(
      {{"time_sec", PointField::UINT32}, {"time_nsec", PointField::UINT32}},
      {{1317013000.0, 412500000.0}, {1317013000.0, 500000000.0}, {1317012999.0, 937500000.0}},
      kStamp);
  const auto c = conv::cloudFromMsg(msg, 1.0);
  EXPECT_EQ(c.time_field, conv::PointTimeField::kTimeSecNsec);
  EXPECT_EQ(times(c), (std::vector<float>{-0.0875f, 0.f, -0.5625f}));
  EXPECT_EQ(c.bad_times, 0);
  // -0.5625 s is beyond the default 0.2 s: counted, not used (the point keeps the stamp's time).
  const auto d = conv::cloudFromMsg(msg);
  EXPECT_EQ(times(d), (std::vector<float>{-0.0875f, 0.f, 0.f}));
  EXPECT_EQ(d.bad_times, 1);
  EXPECT_EQ(d.bad_time_example, -0.5625);
}

TEST(PointTime, ImplausibleTimesAreCountedAndNotUsed) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto c = conv::cloudFromMsg(
      timedCloud({{"time", PointField::FLOAT64}}, {{0.05}, {nan}, {3.5}}, kStamp), 0.2);
  ASSERT_EQ(c.cloud.size(), 3u);  // the points are kept
  EXPECT_EQ(times(c), (std::vector<float>{0.05f, 0.f, 0.f}));
  EXPECT_EQ(c.bad_times, 2);
  EXPECT_TRUE(std::isnan(c.bad_time_example));
  // Ouster's nanoseconds read as seconds would be 5e7 s: every point named.
  const auto s = conv::cloudFromMsg(
      timedCloud({{"time", PointField::UINT32}}, {{0.0}, {50000000.0}, {99000000.0}}, kStamp));
  EXPECT_EQ(s.bad_times, 2);
  EXPECT_EQ(s.bad_time_example, 50000000.0);
}

TEST(PointTime, OneRuleWhenSeveralFieldsArePresent) {
  // `time` wins over `t`; `time_sec` alone is no time.
  const auto c = conv::cloudFromMsg(
      timedCloud({{"t", PointField::UINT32}, {"time", PointField::FLOAT32}}, {{1e6, 0.25}}, kStamp),
      1.0);
  EXPECT_EQ(c.time_field, conv::PointTimeField::kTime);
  EXPECT_FLOAT_EQ(c.cloud[0].time, 0.25f);
  const auto d =
      conv::cloudFromMsg(timedCloud({{"time_sec", PointField::UINT32}}, {{1.0}}, kStamp));
  EXPECT_EQ(d.time_field, conv::PointTimeField::kNone);
  EXPECT_FALSE(d.has_time);
  EXPECT_STREQ(conv::pointTimeFieldName(d.time_field), "none");
}

TEST(PointTime, CountOtherThanOneIsRefused) {
  auto msg = timedCloud({{"t", PointField::UINT32}}, {{0.0}}, kStamp);
  msg.fields[3].count = 2;
  try {
    conv::cloudFromMsg(msg);
    FAIL() << "a 't' field of count 2 accepted";
  } catch (const conv::ConversionError& e) {
    EXPECT_NE(std::string(e.what()).find("field 't' has count 2"), std::string::npos) << e.what();
  }
}

// The real Luminar bag: time_sec + time_nsec absolute, the stamp at the sweep's last point.
TEST(PointTime, LuminarBagSweepsEndAtTheirStamp) {
  LSF_REQUIRE_DATA("bag_luminar/test.bag");
  rosbag::Bag bag(lidar_stereo_fusion::test::dataPath("bag_luminar/test.bag"));
  rosbag::View view(bag, rosbag::TopicQuery("/luminar_pointcloud"));
  int sweeps = 0;
  for (const rosbag::MessageInstance& m : view) {
    const auto msg = m.instantiate<sensor_msgs::PointCloud2>();
    ASSERT_TRUE(msg);
    const auto c = conv::cloudFromMsg(*msg);
    EXPECT_EQ(c.time_field, conv::PointTimeField::kTimeSecNsec);
    EXPECT_EQ(c.bad_times, 0);
    float first = 1.f, last = -1.f;
    for (const auto& p : c.cloud) first = std::min(first, p.time), last = std::max(last, p.time);
    EXPECT_NEAR(last, 0.0, 1e-3) << "sweep " << sweeps;   // ends at its stamp
    EXPECT_GT(last - first, 0.05) << "sweep " << sweeps;  // a sweep of ~90 ms
    EXPECT_LT(last - first, 0.12) << "sweep " << sweeps;
    ++sweeps;
  }
  EXPECT_EQ(sweeps, 5);
}

TEST(PointTime, WritesFuzzSeedsOfEachLayout) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(LSF_BINARY_DIR) / "fuzz_seeds" / "pointcloud2";
  fs::create_directories(dir);
  const std::vector<std::pair<std::string, sensor_msgs::PointCloud2>> seeds = {
      {"time_f32", timedCloud({{"time", PointField::FLOAT32}}, {{-0.05}, {0.0}}, kStamp)},
      {"t_u32", timedCloud({{"t", PointField::UINT32}}, {{0.0}, {5e7}}, kStamp)},
      {"offset_time_u32", timedCloud({{"offset_time", PointField::UINT32}}, {{1e6}}, kStamp)},
      {"timestamp_f64",
       timedCloud({{"timestamp", PointField::FLOAT64}}, {{kStamp.toSec()}}, kStamp)},
      {"time_sec_nsec",
       timedCloud({{"time_sec", PointField::UINT32}, {"time_nsec", PointField::UINT32}},
                  {{1317013000.0, 4e8}}, kStamp)}};
  for (const auto& [name, msg] : seeds) {
    const std::vector<uint8_t> bytes = lsf_fuzz::encodeCloud(msg);
    const auto back = lsf_fuzz::decodeCloud(bytes.data(), bytes.size());
    EXPECT_TRUE(conv::cloudFromMsg(back).has_time) << name;
    std::ofstream(dir / ("time_" + name), std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
  }
}

}  // namespace
