// The fixtures of the rostest of the fusion node (test_fusion_node*.cpp, one gtest binary): the
// process-wide Harness and a test with or without output subscribers, each starting once the
// node's log throttle of earlier warnings has expired.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fusion_test_harness.h"

namespace fusion_test {

/// The process-wide part: the test node's publishers, /rosout and TF (one ROS node per process).
extern std::unique_ptr<Harness> harness;  // defined in test_fusion_node.cpp

/// A test without output subscribers: the node is up and the throttle of earlier warnings expired.
class FusionNodeUnsubscribed : public ::testing::Test {
 protected:
  Harness& h() { return *harness; }
  void SetUp() override {
    ASSERT_TRUE(h().nodeUp(30.0)) << "the fusion outputs were never advertised";
    h().unsubscribeOutputs();
    h().forgetLatestOutputs();
    // Generous: a warning is logged at most once per period per (topic, kind).
    EXPECT_TRUE(h().waitForThrottleExpiry(h().throttlePeriod() + 10.0))
        << "the node kept warning for " << h().throttlePeriod() + 10.0 << " s";
  }
  void TearDown() override { h().unsubscribeOutputs(); }
};

/// A test with every output subscribed and the inputs connected.
class FusionNode : public FusionNodeUnsubscribed {
 protected:
  void SetUp() override {
    FusionNodeUnsubscribed::SetUp();
    if (HasFatalFailure()) return;
    h().subscribeOutputs();
    ASSERT_TRUE(h().outputsConnected());
    ASSERT_TRUE(h().inputsSubscribed(true, 10.0));
  }

  /// Publishes a good set after a bad one stamped `bad` and waits for its outputs; returns the
  /// outputs stamped `bad` by then. The node publishes in stamp order and drops older sets, so
  /// nothing stamped `bad` can come after (no fixed wait). -1 when the good set gave no output.
  int outputsForBadSet(const ros::Time& bad) {
    const ros::Time good = h().nextStamp();
    h().publishSet(SetSpec(), good);
    if (!h().waitForOutputs(good)) {
      ADD_FAILURE() << "no output for a good set after the set stamped " << bad;
      return -1;
    }
    return h().outputsSoFar(bad);
  }

  /// Publishes `spec` again, newly stamped every 2 s, until one of these sets comes out on every
  /// topic (for a transform just sent, which the node may not have yet); ros::Time() on timeout.
  ros::Time publishUntilOutput(const SetSpec& spec, double timeout = 2 * kOutputTimeout) {
    std::vector<ros::Time> sent;
    ros::Time out;
    Harness::waitFor(timeout, [&] {
      sent.push_back(h().nextStamp());
      h().publishSet(spec, sent.back());
      return Harness::waitFor(2.0, [&] {
        for (const auto& stamp : sent) {
          if (h().waitForOutputs(stamp, 0.0)) out = stamp;
        }
        return !out.isZero();
      });
    });
    return out;
  }

  /// After bad input: the process is alive and a good set still gives one output on every topic.
  void expectStillProducing(const std::string& after) {
    EXPECT_TRUE(h().processAlive()) << h().processNode() << " is gone after " << after;
    const ros::Time stamp = h().nextStamp();
    h().publishSet(SetSpec(), stamp);
    EXPECT_TRUE(h().waitForOutputs(stamp)) << "no output for a good set after " << after;
  }
  /// Publishes a good set, waits for its outputs and returns the stats of it.
  lsf::FusionStatsConstPtr goodSetStats() {
    const ros::Time stamp = h().nextStamp();
    h().publishSet(SetSpec(), stamp);
    if (!h().waitForOutputs(stamp)) return nullptr;
    return h().stats();
  }
};

}  // namespace fusion_test
