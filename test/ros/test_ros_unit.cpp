// Unit tests of the ROS layer without a ROS master: message conversions. The same binary holds
// the sweep matching (test_frame_matcher.cpp) and the parameter tables (test_ros_params.cpp).
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <sensor_msgs/image_encodings.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <boost/make_shared.hpp>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/ros/conversions.h"

namespace lsf = lidar_stereo_fusion;
namespace conv = lidar_stereo_fusion::conversions;
using sensor_msgs::PointField;

namespace {

sensor_msgs::ImagePtr makeImage(int width, int height, const std::string& encoding,
                                const std::vector<uint8_t>& pixel) {
  auto msg = boost::make_shared<sensor_msgs::Image>();
  msg->width = width;
  msg->height = height;
  msg->encoding = encoding;
  msg->step = width * static_cast<uint32_t>(pixel.size());
  for (int i = 0; i < width * height; ++i)
    msg->data.insert(msg->data.end(), pixel.begin(), pixel.end());
  return msg;
}

sensor_msgs::CameraInfo info(double fx, double tx, int width = 64, int height = 32) {
  sensor_msgs::CameraInfo c;
  c.width = width;
  c.height = height;
  c.P = {fx, 0, 31.5, tx, 0, fx, 15.5, 0, 0, 0, 1, 0};
  return c;
}

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

// --- images --------------------------------------------------------------------------------------
TEST(Conversions, EveryEncodingGivesBgrOrGrey) {
  // One pixel colour: blue 10, green 20, red 30.
  const std::map<std::string, std::vector<uint8_t>> pixels = {{"bgr8", {10, 20, 30}},
                                                              {"rgb8", {30, 20, 10}},
                                                              {"bgra8", {10, 20, 30, 255}},
                                                              {"rgba8", {30, 20, 10, 255}}};
  for (const auto& kv : pixels) {
    const cv::Mat out = conv::imageToCore(makeImage(4, 3, kv.first, kv.second));
    ASSERT_EQ(out.type(), CV_8UC3) << kv.first;
    EXPECT_EQ(out.at<cv::Vec3b>(2, 3), cv::Vec3b(10, 20, 30)) << kv.first;
  }
  const cv::Mat grey = conv::imageToCore(makeImage(4, 3, "mono8", {77}));
  ASSERT_EQ(grey.type(), CV_8UC1);
  EXPECT_EQ(grey.at<uint8_t>(1, 1), 77);
}

// Issue 25, point 2: a mono view with a colour view is matched as grey on both sides (grey
// replicated into BGR was matched against real colours: 27 % of the pixels off by > 1 px), and
// the note names both encodings.
TEST(Conversions, MixedMonoAndColourPairIsMatchedAsGrey) {
  for (const bool mono_left : {true, false}) {
    cv::Mat left, right;
    std::string note;
    const auto mono = makeImage(4, 3, "mono8", {50});
    const auto colour = makeImage(4, 3, "bgr8", {10, 200, 30});
    conv::stereoPairToCore(mono_left ? mono : colour, mono_left ? colour : mono, left, right,
                           &note);
    ASSERT_EQ(left.type(), CV_8UC1);
    ASSERT_EQ(right.type(), CV_8UC1);
    cv::Mat grey;
    cv::cvtColor(cv::Mat(1, 1, CV_8UC3, cv::Scalar(10, 200, 30)), grey, cv::COLOR_BGR2GRAY);
    EXPECT_EQ((mono_left ? right : left).at<uint8_t>(0, 0), grey.at<uint8_t>(0, 0));
    EXPECT_EQ((mono_left ? left : right).at<uint8_t>(0, 0), 50);
    EXPECT_NE(note.find(mono_left ? "left image is mono8 but right image is bgr8"
                                  : "left image is bgr8 but right image is mono8"),
              std::string::npos)
        << note;
    EXPECT_NE(note.find("grey"), std::string::npos) << note;
  }
  cv::Mat left, right;
  std::string note = "stale";
  conv::stereoPairToCore(makeImage(4, 3, "bgr8", {1, 2, 3}), makeImage(4, 3, "rgb8", {3, 2, 1}),
                         left, right, &note);
  EXPECT_EQ(left.type(), CV_8UC3);  // both colour: kept
  EXPECT_EQ(note, "");
}

TEST(Conversions, BadImagesAreRejectedWithTheReason) {
  try {
    conv::imageToCore(makeImage(4, 3, "16UC1", {0, 0}));
    FAIL() << "16UC1 accepted";
  } catch (const conv::ConversionError& e) {
    EXPECT_NE(std::string(e.what()).find("16UC1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bgra8"), std::string::npos) << "lists the supported";
  }
  auto truncated = makeImage(4, 3, "bgr8", {1, 2, 3});
  truncated->data.resize(10);
  EXPECT_FALSE(conv::checkImage(*truncated).empty());
  EXPECT_THROW(conv::imageToCore(truncated), conv::ConversionError);
  cv::Mat l, r;
  EXPECT_THROW(conv::stereoPairToCore(makeImage(4, 3, "bgr8", {1, 2, 3}),
                                      makeImage(5, 3, "bgr8", {1, 2, 3}), l, r),
               conv::ConversionError);
}

// --- camera --------------------------------------------------------------------------------------
TEST(Conversions, BaselineFromEitherSignOfTx) {
  const double fx = 700.0, B = 0.12;
  for (const double sign : {-1.0, 1.0}) {
    const lsf::StereoCamera c = conv::stereoCameraFromInfo(info(fx, 0.0), info(fx, sign * fx * B));
    EXPECT_DOUBLE_EQ(c.fx, fx);
    EXPECT_DOUBLE_EQ(c.fy, fx);
    EXPECT_DOUBLE_EQ(c.cx, 31.5);
    EXPECT_DOUBLE_EQ(c.cy, 15.5);
    EXPECT_NEAR(c.baseline, B, 1e-12);
    EXPECT_EQ(c.width, 64);
    EXPECT_EQ(c.height, 32);
  }
}

TEST(Conversions, UnusableCameraInfoNamesTheCamera) {
  try {
    conv::stereoCameraFromInfo(info(0.0, 0.0), info(700.0, -84.0));
    FAIL();
  } catch (const conv::ConversionError& e) {
    EXPECT_NE(std::string(e.what()).find("left camera_info"), std::string::npos) << e.what();
  }
  try {
    conv::stereoCameraFromInfo(info(700.0, 0.0), info(700.0, 0.0));  // right = left
    FAIL();
  } catch (const conv::ConversionError& e) {
    EXPECT_NE(std::string(e.what()).find("right camera_info"), std::string::npos) << e.what();
  }
  EXPECT_THROW(conv::stereoCameraFromInfo(info(700.0, 0.0), info(650.0, -84.0)),
               conv::ConversionError);
  EXPECT_THROW(conv::stereoCameraFromInfo(info(700.0, 0.0), info(700.0, -84.0, 32, 32)),
               conv::ConversionError);
}

// Issue 25, point 3: the error says whose camera_info it is, so that the warning goes under that
// topic (checkImageSet).
TEST(Conversions, CameraInfoErrorsSayWhichCamera) {
  sensor_msgs::CameraInfo nan_cx = info(700.0, 0.0);
  nan_cx.P[2] = std::numeric_limits<double>::quiet_NaN();
  sensor_msgs::CameraInfo zero = info(700.0, 0.0);
  zero.K.fill(0.0);
  zero.P.fill(0.0);
  const auto side = [](const sensor_msgs::CameraInfo& l, const sensor_msgs::CameraInfo& r) {
    try {
      conv::stereoCameraFromInfo(l, r);
    } catch (const conv::CameraInfoError& e) {
      return std::string(e.left ? "left" : "right") + ": " + e.what();
    }
    return std::string("accepted");
  };
  EXPECT_EQ(side(info(0.0, 0.0), info(700.0, -84.0)).rfind("left: left camera_info", 0), 0u);
  EXPECT_EQ(side(nan_cx, info(700.0, -84.0)).rfind("left: left camera_info: P[2]", 0), 0u);
  EXPECT_EQ(side(zero, info(700.0, -84.0)).rfind("left: left camera_info", 0), 0u);
  EXPECT_EQ(side(info(700.0, 0.0), zero).rfind("right: right camera_info", 0), 0u);
  EXPECT_EQ(side(info(700.0, 0.0), info(700.0, 0.0)).rfind("right: right camera_info", 0), 0u);
}

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
