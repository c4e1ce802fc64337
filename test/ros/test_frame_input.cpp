// The one frame path of the node and bag_runner (prepareFusionInput, frame_input.h) without a ROS
// master: an accepted set gives exactly the conversions' input, which the pipeline takes; an empty
// sweep, a sweep of NaNs, images of another size than their pair or camera_info, and a missing
// ego-motion are rejected, each with its reason.
#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include <tf2/exceptions.h>
#include <tf2_eigen/tf2_eigen.h>
#include <boost/make_shared.hpp>

#include "lidar_stereo_fusion/ros/conversions.h"
#include "lidar_stereo_fusion/ros/frame_input.h"

namespace lsf = lidar_stereo_fusion;
namespace conv = lidar_stereo_fusion::conversions;

namespace {

constexpr int kWidth = 64, kHeight = 48;
constexpr int kSeed = 7;                                          ///< of the image texture
const ros::Time kImageStamp(100, 0), kSweepStamp(100, 20000000);  // sweep 20 ms after the images

sensor_msgs::ImagePtr imageMsg(const cv::Mat& bgr, const std::string& frame) {
  auto msg = boost::make_shared<sensor_msgs::Image>();
  msg->header.frame_id = frame;
  msg->header.stamp = kImageStamp;
  msg->width = static_cast<uint32_t>(bgr.cols);
  msg->height = static_cast<uint32_t>(bgr.rows);
  msg->encoding = "bgr8";
  msg->step = msg->width * 3;
  for (int r = 0; r < bgr.rows; ++r) {
    msg->data.insert(msg->data.end(), bgr.ptr<uint8_t>(r), bgr.ptr<uint8_t>(r) + msg->step);
  }
  return msg;
}

sensor_msgs::CameraInfoPtr infoMsg(int width, int height, double tx) {
  auto msg = boost::make_shared<sensor_msgs::CameraInfo>();
  msg->header.stamp = kImageStamp;
  msg->width = static_cast<uint32_t>(width);
  msg->height = static_cast<uint32_t>(height);
  msg->P = {50, 0, width / 2.0, tx, 0, 50, height / 2.0, 0, 0, 0, 1, 0};
  return msg;
}

/// A sweep of 16 rings (elevation -15 .. +15 degrees, in ring order) of 64 points each, 10 m
/// around the LiDAR, with the velodyne_pointcloud fields (ring, time over 0 .. 0.1 s).
lsf::LidarCloud ringedCloud() {
  lsf::LidarCloud cloud;
  for (int ring = 0; ring < 16; ++ring) {
    const double elevation = (-15.0 + 2.0 * ring) * M_PI / 180.0;
    for (int k = 0; k < 64; ++k) {
      const double azimuth = 2.0 * M_PI * k / 64.0;
      lsf::LidarPoint p;
      p.x = static_cast<float>(10.0 * std::cos(elevation) * std::cos(azimuth));
      p.y = static_cast<float>(10.0 * std::cos(elevation) * std::sin(azimuth));
      p.z = static_cast<float>(10.0 * std::sin(elevation));
      p.intensity = 1.f;
      p.ring = ring;
      p.time = static_cast<float>(0.1 * k / 64.0);
      cloud.push_back(p);
    }
  }
  return cloud;
}

sensor_msgs::PointCloud2ConstPtr cloudMsg(const lsf::LidarCloud& cloud) {
  std_msgs::Header header;
  header.frame_id = "velodyne";
  header.stamp = kSweepStamp;
  return boost::make_shared<sensor_msgs::PointCloud2>(conv::cloudToMsg(cloud, header));
}

/// A textured stereo pair (the right view the left one shifted by 3 px), its camera_infos (fx 50
/// px, baseline 0.5 m) and the ringed sweep.
lsf::InputMatch goodMatch() {
  cv::Mat left(kHeight, kWidth, CV_8UC3);
  cv::RNG rng(kSeed);
  rng.fill(left, cv::RNG::UNIFORM, 0, 256);
  cv::Mat right = cv::Mat::zeros(left.size(), left.type());
  left(cv::Rect(3, 0, kWidth - 3, kHeight)).copyTo(right(cv::Rect(0, 0, kWidth - 3, kHeight)));
  lsf::InputMatch match;
  match.images.left = imageMsg(left, "left_optical");
  match.images.right = imageMsg(right, "right_optical");
  match.images.left_info = infoMsg(kWidth, kHeight, 0.0);
  match.images.right_info = infoMsg(kWidth, kHeight, -50 * 0.5);
  match.sweep = cloudMsg(ringedCloud());
  match.image_stamp = kImageStamp;
  match.sweep_stamp = kSweepStamp;
  return match;
}

/// LiDAR (x forward, z up) -> left optical frame (z forward, y down), 0.1 m below the camera.
Eigen::Isometry3d lidarToCamera() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  T.translation() << 0, 0.1, 0;
  return T;
}

lsf::PreparedFrame prepare(const lsf::InputMatch& match, const lsf::NodeParams& params = {},
                           const lsf::EgoMotionTf& tf = {}) {
  return lsf::prepareFusionInput(match, lidarToCamera(), params, tf, "/rig/velodyne_points");
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST(FramePath, AcceptedSetGivesTheConversionsInputAndThePipelineTakesIt) {
  const lsf::InputMatch match = goodMatch();
  const lsf::PreparedFrame frame = prepare(match);
  ASSERT_TRUE(frame.accepted()) << frame.reason;
  EXPECT_EQ(frame.reason, "");
  EXPECT_TRUE(frame.notes.empty()) << frame.notes.front().text;

  // Exactly what the conversions and the ring recovery give, step by step.
  cv::Mat left, right;
  conv::stereoPairToCore(match.images.left, match.images.right, left, right);
  EXPECT_EQ(cv::norm(frame.input.left, left, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(frame.input.right, right, cv::NORM_INF), 0.0);
  const lsf::StereoCamera camera =
      conv::stereoCameraFromInfo(*match.images.left_info, *match.images.right_info);
  EXPECT_EQ(frame.input.camera.fx, camera.fx);
  EXPECT_EQ(frame.input.camera.baseline, 0.5);
  EXPECT_EQ(frame.input.camera.width, kWidth);
  EXPECT_EQ(frame.input.camera.height, kHeight);
  EXPECT_TRUE(frame.input.T_cam_lidar.isApprox(lidarToCamera(), 0.0));
  conv::CloudConversion cloud = conv::cloudFromMsg(*match.sweep);
  const lsf::RingRecovery rings = lsf::ensureRings(cloud.cloud, cloud.has_ring, 64);
  ASSERT_EQ(frame.input.cloud.size(), cloud.cloud.size());
  ASSERT_EQ(frame.input.cloud.size(), 16u * 64u);
  for (std::size_t i = 0; i < cloud.cloud.size(); ++i) {
    const lsf::LidarPoint &a = frame.input.cloud[i], &b = cloud.cloud[i];
    ASSERT_TRUE(a.x == b.x && a.y == b.y && a.z == b.z && a.ring == b.ring && a.time == b.time)
        << "point " << i;
  }

  EXPECT_EQ(frame.report.cloud_points, 16 * 64);
  EXPECT_EQ(frame.report.invalid_points, 0);
  EXPECT_EQ(frame.report.rings.source, rings.source);
  EXPECT_EQ(frame.report.rings.rings, 16);
  EXPECT_TRUE(frame.report.rings.plausible);
  EXPECT_EQ(frame.report.point_time_field, "time");
  EXPECT_FALSE(frame.report.motion_compensated);  // no ~fixed_frame
  EXPECT_EQ(frame.report.motion_failure, "");

  const lsf::FusionResult result = lsf::FusionPipeline().process(frame.input);
  EXPECT_EQ(result.disparity.size(), cv::Size(kWidth, kHeight));
  EXPECT_GT(result.stats.points_projected, 0);
}

TEST(FramePath, EmptySweepIsRejectedSayingSo) {
  lsf::InputMatch match = goodMatch();
  match.sweep = cloudMsg({});
  const lsf::PreparedFrame frame = prepare(match);
  EXPECT_EQ(frame.rejection, lsf::FrameRejection::kNoPoints);
  EXPECT_FALSE(frame.accepted());
  EXPECT_EQ(frame.reason, "/rig/velodyne_points: the sweep at 100.020000 has no points");
  EXPECT_STREQ(lsf::rejectionKind(frame.rejection), "nan");
}

TEST(FramePath, SweepOfNaNsIsRejectedCountingThem) {
  lsf::LidarCloud cloud = ringedCloud();
  cloud.resize(5);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (lsf::LidarPoint& p : cloud) p.x = nan;
  cloud[4].x = 1e6f;  // finite, but no LiDAR return
  lsf::InputMatch match = goodMatch();
  match.sweep = cloudMsg(cloud);
  const lsf::PreparedFrame frame = prepare(match);
  EXPECT_EQ(frame.rejection, lsf::FrameRejection::kNoPoints);
  EXPECT_EQ(frame.reason,
            "/rig/velodyne_points: none of the 5 points of the sweep at 100.020000 is finite and "
            "within 10 km (4 NaN / inf, 1 beyond 10 km)");
}

TEST(FramePath, ImagesOfAnotherSizeThanTheirPairOrCameraInfoAreRejected) {
  lsf::InputMatch match = goodMatch();
  cv::Mat narrow(kHeight, kWidth - 2, CV_8UC3, cv::Scalar::all(90));
  match.images.right = imageMsg(narrow, "right_optical");
  lsf::PreparedFrame frame = prepare(match);
  EXPECT_EQ(frame.rejection, lsf::FrameRejection::kConversion);
  EXPECT_STREQ(lsf::rejectionKind(frame.rejection), "convert");
  EXPECT_TRUE(contains(frame.reason, "cannot convert the input set at 100.000000: "))
      << frame.reason;
  EXPECT_TRUE(contains(frame.reason, "left image is 64x48 but right image is 62x48"))
      << frame.reason;

  match = goodMatch();
  match.images.left_info = infoMsg(kWidth / 2, kHeight / 2, 0.0);
  match.images.right_info = infoMsg(kWidth / 2, kHeight / 2, -50 * 0.5);
  frame = prepare(match);
  EXPECT_EQ(frame.rejection, lsf::FrameRejection::kConversion);
  EXPECT_TRUE(contains(frame.reason, "the images are 64x48 but their camera_infos 32x24"))
      << frame.reason;

  match = goodMatch();
  match.images.right_info = infoMsg(kWidth / 2, kHeight / 2, -50 * 0.5);
  frame = prepare(match);
  EXPECT_EQ(frame.rejection, lsf::FrameRejection::kConversion);
  EXPECT_TRUE(contains(frame.reason, "left camera_info is 64x48 but right camera_info is 32x24"))
      << frame.reason;
}

TEST(FramePath, MixedEncodingsAndUnusedPointTimesAreNoted) {
  lsf::InputMatch match = goodMatch();
  auto mono = boost::make_shared<sensor_msgs::Image>(*match.images.left);
  mono->encoding = "mono8";
  mono->step = kWidth;
  mono->data.resize(static_cast<std::size_t>(kWidth) * kHeight);
  match.images.left = mono;
  lsf::LidarCloud cloud = ringedCloud();
  cloud[3].time = 5.f;  // beyond ~max_point_time
  match.sweep = cloudMsg(cloud);
  const lsf::PreparedFrame frame = prepare(match);
  ASSERT_TRUE(frame.accepted()) << frame.reason;
  ASSERT_EQ(frame.notes.size(), 2u);
  EXPECT_EQ(frame.notes[0].kind, "encodings");
  EXPECT_TRUE(contains(frame.notes[0].text, "mono8")) << frame.notes[0].text;
  EXPECT_EQ(frame.notes[1].kind, "time");
  EXPECT_TRUE(contains(frame.notes[1].text, "/rig/velodyne_points: 1 of 1024 points"))
      << frame.notes[1].text;
  EXPECT_EQ(frame.report.bad_times, 1);
  EXPECT_EQ(frame.input.left.type(), CV_8UC1);
  EXPECT_EQ(frame.input.right.type(), CV_8UC1);
}

TEST(FramePath, MissingEgoMotionSkipsOrGoesOnUncompensatedAsConfigured) {
  lsf::NodeParams params;
  params.fixed_frame = "odom";
  params.motion_failure = "skip";
  tf2::BufferCore empty;
  lsf::EgoMotionTf tf;
  tf.buffer = &empty;
  lsf::PreparedFrame frame = prepare(goodMatch(), params, tf);
  EXPECT_EQ(frame.rejection, lsf::FrameRejection::kNoEgoMotion);
  EXPECT_STREQ(lsf::rejectionKind(frame.rejection), "egomotion");
  EXPECT_TRUE(contains(frame.reason,
                       "ego-motion compensation of the sweep at 100.020000 to the "
                       "images at 100.000000 failed: "))
      << frame.reason;
  EXPECT_TRUE(contains(frame.reason, "(~motion_failure: skip)")) << frame.reason;
  EXPECT_NE(frame.report.motion_failure, "");

  params.motion_failure = "uncompensated";
  frame = prepare(goodMatch(), params, tf);
  ASSERT_TRUE(frame.accepted()) << frame.reason;
  ASSERT_EQ(frame.notes.size(), 1u);
  EXPECT_EQ(frame.notes[0].kind, "egomotion");
  EXPECT_TRUE(contains(frame.notes[0].text, "(~motion_failure: uncompensated)"));
  EXPECT_FALSE(frame.report.motion_compensated);
  EXPECT_NE(frame.report.motion_failure, "");
  EXPECT_EQ(frame.input.cloud.size(), 16u * 64u);  // as converted
}

TEST(FramePath, EgoMotionWaitsOnceForTheLatestInstantThenCompensates) {
  // A rig standing still in odom from 99 s to 101 s.
  tf2::BufferCore buffer;
  for (const double t : {99.0, 101.0}) {
    geometry_msgs::TransformStamped odom_lidar =
        tf2::eigenToTransform(Eigen::Isometry3d::Identity());
    odom_lidar.header.frame_id = "odom";
    odom_lidar.header.stamp = ros::Time(t);
    odom_lidar.child_frame_id = "velodyne";
    buffer.setTransform(odom_lidar, "test");
  }
  lsf::NodeParams params;
  params.fixed_frame = "odom";
  params.motion_failure = "skip";
  std::vector<ros::Time> waited;
  lsf::EgoMotionTf tf;
  tf.buffer = &buffer;
  tf.wait = [&](const std::string& fixed, const std::string& lidar, const ros::Time& latest) {
    EXPECT_EQ(fixed, "odom");
    EXPECT_EQ(lidar, "velodyne");
    waited.push_back(latest);
  };
  lsf::PreparedFrame frame = prepare(goodMatch(), params, tf);
  ASSERT_TRUE(frame.accepted()) << frame.reason;
  EXPECT_TRUE(frame.report.motion_compensated);
  EXPECT_EQ(frame.report.motion_failure, "");
  // The sweep's last point is 0.1 s * 63 / 64 after its stamp, itself after the images.
  ASSERT_EQ(waited.size(), 1u);
  EXPECT_NEAR((waited[0] - kSweepStamp).toSec(), 0.1 * 63 / 64, 1e-6);

  // A wait that gives up is a missing ego-motion like any other.
  tf.wait = [](const std::string&, const std::string&, const ros::Time&) {
    throw tf2::TransformException("waited 0.05 s in vain");
  };
  frame = prepare(goodMatch(), params, tf);
  EXPECT_EQ(frame.rejection, lsf::FrameRejection::kNoEgoMotion);
  EXPECT_TRUE(contains(frame.reason, "waited 0.05 s in vain")) << frame.reason;
}
