// rostest of the fusion node (see test_fusion_node.cpp): the inputs of issues 9 and 25 (messages
// that once crashed the manager, the log throttle per topic and kind, an integer coordinate field,
// mixed encodings, an uncalibrated left camera_info, invalid points of a valid sweep), and the
// checks that run only under fusion_max_rate.test (~max_rate) and fusion_approx_sync.test.
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <ros/ros.h>

#include "fusion_node_fixtures.h"
#include "fusion_test_harness.h"
#include "lidar_stereo_fusion/FusionStats.h"
#include "synthetic_input.h"

namespace lsf = lidar_stereo_fusion;
using namespace fusion_test;  // NOLINT: the harness of these tests

// Crashes 1 and 2 of issue 9, through the node: a PointCloud2 field at offset 2^32 - 4 (read 4 GiB
// past the buffer) and a bgra8 image 2^30 wide with step 1 (width * channels wrapped, uncaught
// cv::Exception). Both are rejected with a warning naming the topic; the process lives on.
TEST_F(FusionNode, MessagesThatOnceCrashedTheManagerAreRejected) {
  const auto& frame = h().frames().front();
  auto cloud = lsf::test::cloudMsg(frame.cloud, kLidarFrame, ros::Time());
  for (auto& f : cloud->fields) {
    if (f.name == "intensity") f.offset = 4294967292u;
  }
  SetSpec bad_cloud;
  bad_cloud.cloud = SetSpec::Cloud::kCustom;
  bad_cloud.custom_cloud = cloud;
  std::size_t mark = h().logMark();
  ros::Time stamp = h().nextStamp();
  h().publishSet(bad_cloud, stamp);
  EXPECT_TRUE(h().waitForLog(mark, {"velodyne_points", "4294967292"})) << h().logsSince(mark);
  EXPECT_EQ(outputsForBadSet(stamp), 0);
  expectStillProducing("a cloud field at offset 2^32 - 4");

  auto wide = boost::make_shared<sensor_msgs::Image>();
  wide->encoding = "bgra8";
  wide->width = 1u << 30;
  wide->height = 1;
  wide->step = 1;
  wide->data.assign(64, 0);
  SetSpec bad_image;
  bad_image.custom_left = wide;
  mark = h().logMark();
  stamp = h().nextStamp();
  h().publishSet(bad_image, stamp);
  EXPECT_TRUE(h().waitForLog(mark, {"left/image_rect_color", "1073741824"})) << h().logsSince(mark);
  EXPECT_EQ(outputsForBadSet(stamp), 0);
  expectStillProducing("a bgra8 image 2^30 pixels wide");
}

// Issue 9, point 9: the throttle keys on (topic, kind of problem), not on the text, so clouds whose
// message varies (a byte count) give one line per ~log_throttle_period, and another kind on the
// same topic is not hidden by it. (The fixture waited until earlier warnings expired.)
TEST_F(FusionNode, ThrottlePerTopicAndKindNotPerText) {
  const auto& frame = h().frames().front();
  const std::size_t mark = h().logMark();
  const auto start = ros::WallTime::now();
  for (int i = 0; i < 10; ++i) {
    auto cloud = lsf::test::cloudMsg(frame.cloud, kLidarFrame, ros::Time());
    cloud->data.resize(cloud->data.size() - 1 - i);  // truncated by a different byte count
    SetSpec spec;
    spec.cloud = SetSpec::Cloud::kCustom;
    spec.custom_cloud = cloud;
    h().publishSet(spec, h().nextStamp());
  }
  SetSpec empty;
  empty.cloud = SetSpec::Cloud::kEmpty;
  h().publishSet(empty, h().nextStamp());
  // The sweeps are refused in order on one subscription, and /rosout of one process keeps the
  // order: once the line of the last (empty) sweep is here, every earlier line is here too.
  EXPECT_TRUE(h().waitForLog(mark, {"velodyne_points", "empty"})) << "hidden by the other kind";
  ASSERT_LT((ros::WallTime::now() - start).toSec(), h().throttlePeriod())
      << "the sweeps took longer than ~log_throttle_period: raise it in the .test file";
  int truncated_lines = 0;
  for (const std::string& line : h().warningsSince(mark)) {
    // The refusals themselves (the image sets left without a sweep say so in their own kind).
    truncated_lines += line.find("/velodyne_points: data has") != std::string::npos;
  }
  EXPECT_EQ(truncated_lines, 1) << h().logsSince(mark);
  expectStillProducing("truncated clouds");
}

// Only in fusion_max_rate.test (~max_rate 2 Hz): image sets stamped 0.1 s apart are dropped on
// arrival except one per 0.45 s (0.9 / max_rate), counted in stats, without a warning.
TEST_F(FusionNode, MaxRate_FasterSetsAreDroppedAndCounted) {
  const ros::Time first = h().nextStamp();
  h().publishSet(SetSpec(), first);
  ASSERT_TRUE(h().waitForOutputs(first));
  const uint32_t limited = h().stats()->rate_limited;
  const std::size_t mark = h().logMark();
  std::vector<ros::Time> stamps;
  for (int k = 1; k <= 5; ++k) {
    stamps.push_back(first + ros::Duration(0.1 * k));
    h().publishSet(SetSpec(), stamps.back());
  }
  ASSERT_TRUE(h().waitForOutputs(stamps.back())) << "the set 0.5 s after the first is let through";
  // Published in stamp order: the dropped ones would have come before the last one.
  for (int k = 0; k < 4; ++k) EXPECT_EQ(h().outputsSoFar(stamps[k]), 0) << "set " << k + 1;
  EXPECT_EQ(h().stats()->rate_limited, limited + 4);
  EXPECT_FALSE(h().waitForLog(mark, {"max_rate"}, 0.5)) << h().logsSince(mark);
}

// Only in fusion_approx_sync.test: right image and info stamped 4 ms after the left ones.
TEST_F(FusionNode, Approx_SetsWithDifferentStampsAreMatched) {
  // ApproximateTime releases a set once a later message on every topic shows that no better
  // match can come, so set i comes out when set i + 1 is published.
  constexpr int kSets = 6;
  std::vector<ros::Time> stamps;
  for (int i = 0; i < kSets; ++i) {
    SetSpec spec;
    spec.frame = i;
    spec.right_stamp_offset = 0.004;
    const ros::Time stamp = h().nextStamp();
    stamps.push_back(stamp);
    h().publishSet(spec, stamp);
    if (i > 0) {
      EXPECT_TRUE(h().waitForOutputs(stamps[i - 1])) << "set " << i - 1 << " of " << kSets;
    }
  }
  for (const auto& stamp : stamps) {
    for (const auto& name : kOutputs) {
      EXPECT_LE(h().count(name, stamp), 1) << name;
      EXPECT_EQ(h().count(name, stamp + ros::Duration(0.004)), 0)
          << name << " stamped with the right image, not the left";
    }
  }
}

// Issue 25, point 1: a coordinate field of an integer type was read as metres (a UINT8 'x' put
// 95,129 points in front of the camera): refused, naming the field and its type; and the image set
// left without a sweep says the sweep was refused (point 4), not that the LiDAR is silent.
TEST_F(FusionNode, IntegerCoordinateFieldIsRefusedNamingItAndTheSetSaysSo) {
  SetSpec spec;
  spec.cloud = SetSpec::Cloud::kCustom;
  spec.custom_cloud = h().makeCloud(SetSpec(), ros::Time(1));
  spec.custom_cloud->fields[0].datatype = sensor_msgs::PointField::UINT8;  // 'x'
  const std::size_t mark = h().logMark();
  const ros::Time stamp = h().nextStamp();
  h().publishSet(spec, stamp);
  EXPECT_TRUE(h().waitForLog(mark, {"velodyne_points", "'x'", "UINT8"})) << h().logsSince(mark);
  EXPECT_TRUE(h().waitForLog(mark, {"no usable sweep", "refused", "'x'"})) << h().logsSince(mark);
  EXPECT_EQ(outputsForBadSet(stamp), 0);
  EXPECT_FALSE(h().waitForLog(mark, {"is the LiDAR publishing"}, 0.1)) << h().logsSince(mark);
  expectStillProducing("a UINT8 x field");
}

// Issue 25, point 2: left bgr8 with right mono8 is matched as grey on both sides, said once, and
// gives exactly the disparity of the same pair given as mono8 on both sides.
TEST_F(FusionNode, MixedEncodingsAreMatchedAsGreyAndSaidOnce) {
  SetSpec mono;
  mono.left_encoding = mono.right_encoding = "mono8";
  ros::Time stamp = h().nextStamp();
  h().publishSet(mono, stamp);
  ASSERT_TRUE(h().waitForOutputs(stamp));
  const auto grey = h().image("disparity_image");
  ASSERT_TRUE(grey);
  ASSERT_EQ(grey->header.stamp, stamp);
  const std::vector<uint8_t> grey_pixels = grey->data;
  SetSpec mixed;
  mixed.right_encoding = "mono8";
  const std::size_t mark = h().logMark();
  for (int i = 0; i < 2; ++i) {
    stamp = h().nextStamp();
    h().publishSet(mixed, stamp);
    ASSERT_TRUE(h().waitForOutputs(stamp)) << "mixed set " << i;
  }
  const auto mixed_out = h().image("disparity_image");
  ASSERT_TRUE(mixed_out);
  EXPECT_TRUE(mixed_out->data == grey_pixels) << "the mixed pair differs from the grey pair";
  EXPECT_TRUE(h().waitForLog(mark, {"bgr8", "mono8", "grey"})) << h().logsSince(mark);
  const std::string said = h().logsSince(mark);
  EXPECT_EQ(said.find("mono8"), said.rfind("mono8")) << "said more than once:" << said;
}

// Issue 25, point 3: a left camera_info without a calibration is reported under the left topic.
TEST_F(FusionNode, LeftCameraInfoProblemsAreReportedUnderTheLeftTopic) {
  SetSpec spec;
  spec.left_info_zero = true;
  const std::size_t mark = h().logMark();
  const ros::Time stamp = h().nextStamp();
  h().publishSet(spec, stamp);
  EXPECT_TRUE(h().waitForLog(mark, {"left/camera_info: left camera_info"})) << h().logsSince(mark);
  EXPECT_EQ(outputsForBadSet(stamp), 0);
  EXPECT_FALSE(h().waitForLog(mark, {"right/camera_info: left camera_info"}, 0.1))
      << h().logsSince(mark);
  expectStillProducing("an uncalibrated left camera_info");
}

// Issue 25, point 7: points dropped as NaN / inf or beyond 10 km are counted in the stats.
TEST_F(FusionNode, InvalidPointsOfAValidSweepAreCounted) {
  const auto base = h().makeCloud(SetSpec(), ros::Time(1));
  SetSpec spec;
  spec.cloud = SetSpec::Cloud::kCustom;
  spec.custom_cloud = boost::make_shared<sensor_msgs::PointCloud2>(*base);
  const auto put = [&](std::size_t point, std::size_t field, float value) {
    std::memcpy(&spec.custom_cloud->data[point * spec.custom_cloud->point_step +
                                         spec.custom_cloud->fields[field].offset],
                &value, sizeof(float));
  };
  put(0, 0, 1e38f);                                    // x = 1e38
  put(1, 2, std::numeric_limits<float>::infinity());   // z = inf
  put(2, 1, std::numeric_limits<float>::quiet_NaN());  // y = NaN
  const ros::Time stamp = h().nextStamp();
  h().publishSet(spec, stamp);
  ASSERT_TRUE(h().waitForOutputs(stamp));
  ASSERT_TRUE(h().stats());
  EXPECT_EQ(h().stats()->header.stamp, stamp);
  EXPECT_EQ(h().stats()->points_invalid, 3);
  EXPECT_EQ(h().stats()->points_in_cloud, static_cast<int>(base->width * base->height) - 3);
}

// Only in fusion_keep_rate.test (~keep_rate true, the default preset): sets arriving faster than
// the worker finishes them are dropped, and the search gives up effort above the LiDAR, saying
// why; the outputs go on.
TEST_F(FusionNode, KeepRate_DroppedSetsMakeTheSearchCoarserAndTheNodeSaysWhy) {
  const std::size_t mark = h().logMark();
  const uint32_t dropped = h().stats() ? h().stats()->dropped_frames : 0;
  bool said = false;
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(60.0);
  ros::Time last;
  while (!said && ros::WallTime::now() < deadline) {
    // A burst of sets 1 ms apart: the worker is busy with one while the next ones come.
    for (int k = 0; k < 10; ++k) {
      last = h().nextStamp();
      h().publishSet(SetSpec(), last);
      ros::WallDuration(0.001).sleep();
    }
    h().waitForOutputs(last, 5.0);
    said = h().waitForLog(
        mark,
        {"keep_rate", "dropped input sets", "step 1 of 4", "the right view not refined between"},
        0.5);
  }
  ASSERT_TRUE(said) << h().logsSince(mark);
  ASSERT_TRUE(h().stats());
  EXPECT_GT(h().stats()->dropped_frames, dropped);
  expectStillProducing("the search reduced by keep_rate");
}
