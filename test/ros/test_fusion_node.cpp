// rostest of lidar_stereo_fusion/FusionNodelet, run against the nodelet (fusion_nodelet.test),
// the fusion_node executable (fusion_node.test) and with approximate sync
// (fusion_approx_sync.test). The test publishes synthetic input itself: frames of the simulated
// street (320 x 120, sim::generateStreetFrame) with a static LiDAR -> camera transform, plus bad
// input of every kind, and checks the outputs, the warnings on /rosout and that the process keeps
// producing output after each bad input.
//
// Private parameters: ~process_node (the node whose process hosts the nodelet: the manager, or
// fusion_node itself), ~fusion_node (the nodelet / node name, for its parameters and services).
//
// The tests need no order (they pass under --gtest_shuffle): each one subscribes the outputs it
// needs, makes its own reference frames and waits on conditions with deadlines, never a fixed time.
// Every test starts once the node's log throttle (~log_throttle_period, short in the .test files)
// has expired, so a warning a test expects is not hidden by one of an earlier test.
//
// The tests are split by what they check, into one gtest binary (cmake/ros_tests.cmake): this file
// (lazy subscription, the thread-count cap, the outputs of good input sets and main()),
// test_fusion_node_input.cpp (sweep timing, TF, bad images and clouds, stamp order, clouds
// without rings), test_fusion_node_params.cpp (live parameters, diagnostics) and
// test_fusion_node_issues.cpp (inputs of issues 9 and 25, ~max_rate, approximate sync).
// fusion_node_fixtures.h holds the fixtures, fusion_test_harness.h the harness.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <ros/master.h>
#include <ros/ros.h>
#include <sensor_msgs/image_encodings.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include "fusion_node_fixtures.h"
#include "fusion_test_harness.h"
#include "lidar_stereo_fusion/FusionStats.h"
#include "synthetic_input.h"

namespace lsf = lidar_stereo_fusion;
using namespace fusion_test;  // NOLINT: the harness of these tests

namespace fusion_test {
std::unique_ptr<Harness> harness;
}  // namespace fusion_test

namespace {

/// Median |depth - truth| / truth over pixels where both have a value, and the fraction of the
/// pixels with truth that have a value.
void depthError(const sensor_msgs::Image& depth, const cv::Mat1f& truth, double* median_rel,
                double* coverage) {
  std::vector<double> errors;
  int with_truth = 0;
  for (int r = 0; r < truth.rows; ++r) {
    const float* row = reinterpret_cast<const float*>(&depth.data[r * depth.step]);
    for (int c = 0; c < truth.cols; ++c) {
      const float t = truth(r, c);
      if (!(t > 0.f) || t > 60.f) continue;
      ++with_truth;
      if (std::isfinite(row[c])) errors.push_back(std::abs(row[c] - t) / t);
    }
  }
  *coverage = with_truth > 0 ? static_cast<double>(errors.size()) / with_truth : 0.0;
  if (errors.empty()) {
    *median_rel = 1.0;
    return;
  }
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  *median_rel = errors[errors.size() / 2];
}

}  // namespace

// -------------------------------------------------------------------------------------------------
TEST_F(FusionNodeUnsubscribed, LazySubscription) {
  // Without output subscribers (the fixture's; an earlier test's leave), the inputs are dropped
  // and stay dropped.
  ASSERT_TRUE(h().inputsSubscribed(false, 10.0)) << "inputs subscribed without output subscribers";
  EXPECT_FALSE(Harness::waitFor(0.5, [&] { return !h().inputsSubscribed(false, 0.0); }))
      << "inputs subscribed again without output subscribers";

  // Ask the master too: nobody subscribes to the left image.
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  ASSERT_TRUE(ros::master::execute("getSystemState", request, response, payload, true));
  const XmlRpc::XmlRpcValue& subscribers = payload[1];
  for (int i = 0; i < subscribers.size(); ++i) {
    const std::string topic = static_cast<std::string>(subscribers[i][0]);
    EXPECT_NE(topic, "/stereo/left/image_rect_color")
        << "the master lists subscribers of the left image: " << subscribers[i].toXml();
  }

  // One subscriber on one output is enough; when it leaves, the inputs are dropped again.
  for (const std::string output : {"stats", "depth/image_rect", "points2"}) {
    h().subscribeOutputs({output});
    EXPECT_TRUE(h().inputsSubscribed(true, 10.0)) << "no input subscription for " << output;
    h().unsubscribeOutputs();
    EXPECT_TRUE(h().inputsSubscribed(false, 10.0)) << "inputs still subscribed after " << output;
  }
}

// Crash 3 of issue 9: the .test files set ~num_threads (fusion_node.test: under its deprecated
// name ~patchmatch/num_threads) to 100000 through rosparam (~expect_num_threads_rejected); libgomp
// crashed at the first frame. The node keeps the default, says so, and writes the value in use
// back to the parameter server under the one name; the deprecated spelling is gone (issue 10).
TEST_F(FusionNodeUnsubscribed, ThreadCountBeyondTheCapIsNotApplied) {
  ros::NodeHandle pnh("~");
  if (!pnh.param("expect_num_threads_rejected", false)) GTEST_SKIP() << "not set in this .test";
  int threads = -1;
  ASSERT_TRUE(Harness::waitFor(30.0, [&] {
    return ros::param::get(h().fusionNode() + "/num_threads", threads) && threads != 100000;
  })) << "the node did not replace num_threads 100000 by the value in use";
  EXPECT_GE(threads, 0);
  EXPECT_LE(threads, 256);
  EXPECT_FALSE(ros::param::has(h().fusionNode() + "/patchmatch/num_threads"));
  EXPECT_FALSE(ros::param::has(h().fusionNode() + "/patchmatch_num_threads"));
  EXPECT_TRUE(h().processAlive());
}

TEST_F(FusionNode, OneOutputPerInputSetOnEveryTopic) {
  const std::vector<std::string> encodings = {"bgr8", "bgra8", "rgb8", "rgba8", "mono8"};
  uint32_t last_processed = 0;
  std::vector<ros::Time> stamps;
  for (std::size_t i = 0; i < encodings.size(); ++i) {
    SetSpec spec;
    spec.frame = static_cast<int>(i);
    spec.left_encoding = spec.right_encoding = encodings[i];
    spec.positive_tx = (i == 1);                      // both sign conventions of the right P[3]
    const ros::Time stamp = h().nextStampNotAhead();  // latency_ms > 0 below
    stamps.push_back(stamp);
    h().publishSet(spec, stamp);
    ASSERT_TRUE(h().waitForOutputs(stamp)) << "no complete output for " << encodings[i];
    for (const auto& name : kOutputs) EXPECT_EQ(h().frameId(name), kCameraFrame) << name;
    const auto& frame = h().frames()[i % h().frames().size()];

    auto disparity = h().disparity();
    EXPECT_NEAR(disparity->f, frame.camera.fx, 1e-3);
    EXPECT_NEAR(disparity->T, frame.camera.baseline, 1e-6);
    EXPECT_GT(disparity->min_disparity, 0.f);
    EXPECT_GT(disparity->max_disparity, disparity->min_disparity);
    EXPECT_GT(disparity->delta_d, 0.f);
    EXPECT_EQ(disparity->image.encoding, sensor_msgs::image_encodings::TYPE_32FC1);
    EXPECT_EQ(disparity->image.width, static_cast<uint32_t>(kWidth));
    EXPECT_GT(disparity->valid_window.width, 0u);
    EXPECT_LE(disparity->valid_window.x_offset + disparity->valid_window.width,
              static_cast<uint32_t>(kWidth));

    auto depth = h().image("depth/image_rect");
    ASSERT_TRUE(depth);
    EXPECT_EQ(depth->encoding, sensor_msgs::image_encodings::TYPE_32FC1);
    double median_rel = 1, coverage = 0;
    depthError(*depth, frame.depth, &median_rel, &coverage);
    EXPECT_LT(median_rel, 0.05) << "depth is off on the synthetic street (" << encodings[i] << ")";
    EXPECT_GT(coverage, 0.5) << encodings[i];

    auto info = h().depthInfo();
    EXPECT_NEAR(info->P[0], frame.camera.fx, 1e-6);
    EXPECT_EQ(info->width, static_cast<uint32_t>(kWidth));

    auto points = h().points();
    EXPECT_GT(points->width * points->height, 1000u);
    std::set<std::string> fields;
    for (const auto& f : points->fields) fields.insert(f.name);
    EXPECT_EQ(fields, (std::set<std::string>{"x", "y", "z", "rgb"}));

    auto prior = h().image("lidar_disparity");
    int prior_pixels = 0;
    for (std::size_t k = 0; k + 4 <= prior->data.size(); k += 4) {
      float v;
      std::memcpy(&v, &prior->data[k], 4);
      prior_pixels += v > 0.f;
    }
    EXPECT_GT(prior_pixels, kWidth * kHeight / 5);

    // The prior's confidence: 32FC1, unitless in [0, 1], the image's size (all 0 while the core
    // gives none).
    auto confidence = h().image("confidence");
    ASSERT_TRUE(confidence);
    EXPECT_EQ(confidence->encoding, sensor_msgs::image_encodings::TYPE_32FC1);
    EXPECT_EQ(confidence->width, static_cast<uint32_t>(kWidth));
    EXPECT_EQ(confidence->height, static_cast<uint32_t>(kHeight));
    for (std::size_t k = 0; k + 4 <= confidence->data.size(); k += 4) {
      float v;
      std::memcpy(&v, &confidence->data[k], 4);
      if (!(v >= 0.f && v <= 1.f)) {
        ADD_FAILURE() << "confidence " << v << " outside [0, 1] at byte " << k;
        break;
      }
    }

    auto stats = h().stats();
    EXPECT_EQ(stats->method, "fused_bi");
    EXPECT_GT(stats->points_projected, 500);
    EXPECT_EQ(stats->rings, 64);
    EXPECT_FALSE(stats->rings_recovered);
    EXPECT_EQ(stats->ring_method, "ring_field");
    EXPECT_TRUE(stats->rings_plausible);
    EXPECT_GT(stats->processed_frames, last_processed);
    EXPECT_GT(stats->total_ms, 0.f);
    EXPECT_GT(stats->latency_ms, 0.f);
    last_processed = stats->processed_frames;
  }
  // Duplicates would have come before the outputs of a later set (published in stamp order).
  const ros::Time last = h().nextStamp();
  h().publishSet(SetSpec(), last);
  ASSERT_TRUE(h().waitForOutputs(last));
  for (std::size_t i = 0; i < stamps.size(); ++i) {
    for (const auto& name : kOutputs) {
      EXPECT_EQ(h().count(name, stamps[i]), 1) << name << " for " << encodings[i];
    }
  }
}

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_fusion_node");
  ros::AsyncSpinner spinner(3);
  spinner.start();
  harness = std::make_unique<Harness>();
  const int result = RUN_ALL_TESTS();
  harness.reset();
  spinner.stop();
  ros::shutdown();
  return result;
}
