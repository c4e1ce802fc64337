// The sweep matcher (ros/frame_matcher.h) without a ROS master: which sweep an image set gets,
// how long it waits in ROS time, and what out-of-order stamps and bag loops do.
#include <gtest/gtest.h>

#include <ros/time.h>

#include "lidar_stereo_fusion/ros/frame_matcher.h"

namespace lsf = lidar_stereo_fusion;

// --- sweep matching ------------------------------------------------------------------------------
using Matcher = lsf::FrameMatcher<int, int>;

TEST(FrameMatcher, SweepStampedAfterTheImageArrivingLater) {
  Matcher m;
  const ros::Time now(100.0);
  auto ev = m.addSweep(ros::Time(9.95), 1, now);  // previous sweep
  ev = m.addImages(ros::Time(10.0), 100, now);
  EXPECT_TRUE(ev.ready.empty()) << "must wait: a later sweep may be nearer";
  ev = m.addSweep(ros::Time(10.08), 2, now);
  ASSERT_EQ(ev.ready.size(), 1u);
  EXPECT_EQ(ev.ready[0].images, 100);
  EXPECT_EQ(ev.ready[0].sweep, 1) << "9.95 is nearer than 10.08";
}

TEST(FrameMatcher, NearestOfBothSidesWithinTheOffset) {
  Matcher m;
  const ros::Time now(100.0);
  m.addSweep(ros::Time(9.85), 1, now);
  m.addImages(ros::Time(10.0), 100, now);
  auto ev = m.addSweep(ros::Time(10.07), 2, now);
  ASSERT_EQ(ev.ready.size(), 1u);
  EXPECT_EQ(ev.ready[0].sweep, 2);
  EXPECT_EQ(ev.ready[0].sweep_stamp, ros::Time(10.07));
}

TEST(FrameMatcher, SweepAlreadyThere) {
  Matcher m;
  const ros::Time now(100.0);
  m.addSweep(ros::Time(10.0), 1, now);
  auto ev = m.addImages(ros::Time(10.0), 100, now);
  ASSERT_EQ(ev.ready.size(), 1u);
  EXPECT_EQ(ev.ready[0].sweep, 1);
}

TEST(FrameMatcher, EarlierSweepIsTakenAfterWaiting) {
  Matcher::Params p;
  p.max_wait = 0.2;
  Matcher m(p);
  const ros::Time now(100.0);
  m.addSweep(ros::Time(9.95), 1, now);
  EXPECT_TRUE(m.addImages(ros::Time(10.0), 100, now).ready.empty());
  EXPECT_TRUE(m.poll(now + ros::Duration(0.1)).ready.empty());
  auto ev = m.poll(now + ros::Duration(0.25));
  ASSERT_EQ(ev.ready.size(), 1u);
  EXPECT_EQ(ev.ready[0].sweep, 1);
}

// Issue 9, point 4: under `rosbag play -r 0.05` the sweep stamped 30 ms after the images arrives
// 0.6 s of wall time later. The wait is in ROS (simulated) time, so the set still gets its own
// sweep, whatever the playback rate; only ROS time moving past the wait decides it without one.
TEST(FrameMatcher, WaitIsInRosTimeSoThePlaybackRateDoesNotMatter) {
  for (const double rate : {0.05, 0.2, 1.0, 5.0}) {
    SCOPED_TRACE("rate " + std::to_string(rate));
    Matcher m;  // max_wait 0.3 s, max_time_offset 0.1 s
    // Sim time = stamps; what wall time passes in between does not enter at all.
    m.addSweep(ros::Time(9.93), 1, ros::Time(9.93));  // the previous sweep, within the offset
    EXPECT_TRUE(m.addImages(ros::Time(10.0), 100, ros::Time(10.0)).ready.empty());
    EXPECT_TRUE(m.poll(ros::Time(10.029)).ready.empty()) << "decided before its sweep came";
    auto ev = m.addSweep(ros::Time(10.03), 2, ros::Time(10.03));
    ASSERT_EQ(ev.ready.size(), 1u);
    EXPECT_EQ(ev.ready[0].sweep, 2) << "paired with the previous sweep";
  }
  // A paused bag (sim time stands still) never gives up; time moving past the wait does.
  Matcher m;
  m.addSweep(ros::Time(9.95), 1, ros::Time(9.95));
  m.addImages(ros::Time(10.0), 100, ros::Time(10.0));
  EXPECT_TRUE(m.poll(ros::Time(10.0)).ready.empty());
  EXPECT_TRUE(m.poll(ros::Time(10.29)).ready.empty());
  auto ev = m.poll(ros::Time(10.31));
  ASSERT_EQ(ev.ready.size(), 1u);
  EXPECT_EQ(ev.ready[0].sweep, 1);
}

// Under /use_sim_time ROS time is zero until the first /clock, and a bag's first image set can
// arrive before it. The clock's first tick (from zero to the bag's time) is not a wait: the set
// still gets the sweep that comes after it, and gives up only max_wait after the first known time.
TEST(FrameMatcher, SetArrivingBeforeTheFirstClockWaitsFromTheFirstKnownTime) {
  Matcher m;  // max_wait 0.3 s
  EXPECT_TRUE(m.addImages(ros::Time(10.0), 100, ros::Time(0)).ready.empty());
  EXPECT_TRUE(m.poll(ros::Time(0)).unmatched.empty());
  EXPECT_TRUE(m.poll(ros::Time(10.002)).unmatched.empty()) << "given up at the clock's first tick";
  EXPECT_TRUE(m.poll(ros::Time(10.2)).unmatched.empty());
  auto ev = m.addSweep(ros::Time(10.04), 2, ros::Time(10.21));
  ASSERT_EQ(ev.ready.size(), 1u);
  EXPECT_EQ(ev.ready[0].sweep, 2);

  Matcher late;
  late.addImages(ros::Time(10.0), 100, ros::Time(0));
  EXPECT_TRUE(late.poll(ros::Time(10.002)).unmatched.empty());
  EXPECT_TRUE(late.poll(ros::Time(10.3)).unmatched.empty());
  ev = late.poll(ros::Time(10.303));
  ASSERT_EQ(ev.unmatched.size(), 1u);
  EXPECT_TRUE(ev.unmatched_waited[0]);
}

TEST(FrameMatcher, NoSweepWithinTheOffsetIsUnmatched) {
  Matcher m;  // max_time_offset 0.1
  const ros::Time now(100.0);
  m.addSweep(ros::Time(9.8), 1, now);
  m.addImages(ros::Time(10.0), 100, now);
  auto ev = m.addSweep(ros::Time(10.15), 2, now);
  EXPECT_TRUE(ev.ready.empty());
  ASSERT_EQ(ev.unmatched.size(), 1u);
  EXPECT_EQ(ev.unmatched[0], ros::Time(10.0));
  EXPECT_FALSE(ev.unmatched_waited.at(0)) << "a later sweep came: max_time_offset, not the wait";
  // Nothing at or after the set within the wait: decided by max_sweep_wait.
  m.addImages(ros::Time(11.0), 101, now);
  ev = m.poll(now + ros::Duration(0.5));
  ASSERT_EQ(ev.unmatched.size(), 1u);
  EXPECT_TRUE(ev.unmatched_waited.at(0));
  EXPECT_EQ(m.pendingCount(), 0u);
}

TEST(FrameMatcher, OutOfOrderAndDuplicateStampsAreRejected) {
  Matcher m;
  const ros::Time now(100.0);
  EXPECT_FALSE(m.addSweep(ros::Time(10.0), 1, now).out_of_order);
  EXPECT_TRUE(m.addSweep(ros::Time(9.9), 2, now).out_of_order);
  EXPECT_TRUE(m.addSweep(ros::Time(10.0), 3, now).out_of_order);
  EXPECT_FALSE(m.addImages(ros::Time(10.0), 100, now).out_of_order);
  EXPECT_TRUE(m.addImages(ros::Time(9.9), 101, now).out_of_order);
  EXPECT_TRUE(m.addImages(ros::Time(10.0), 102, now).out_of_order);
  m.clear();
  EXPECT_FALSE(m.addImages(ros::Time(5.0), 103, now).out_of_order) << "clear() forgets stamps";
}

TEST(FrameMatcher, LargeStepBackIsARestartNotDisorder) {
  Matcher m;  // restart_step 1 s
  const ros::Time now(100.0);
  m.addSweep(ros::Time(20.0), 1, now);
  m.addImages(ros::Time(20.0), 100, now);
  m.addImages(ros::Time(20.5), 101, now);            // waits for a later sweep
  auto ev = m.addImages(ros::Time(10.0), 102, now);  // a bag loop starts again
  EXPECT_TRUE(ev.restarted);
  EXPECT_FALSE(ev.out_of_order);
  EXPECT_EQ(ev.discarded, 1u);
  ev = m.addSweep(ros::Time(10.04), 2, now);  // stale sweeps are gone: matches
  ASSERT_EQ(ev.ready.size(), 1u);
  EXPECT_EQ(ev.ready[0].images, 102);
  // A sweep from before the restart arriving late pushes the newest stamp up; the next real one
  // is then again a restart, not out of order.
  m.addSweep(ros::Time(20.6), 3, now);
  ev = m.addSweep(ros::Time(10.5), 4, now);
  EXPECT_TRUE(ev.restarted);
  EXPECT_FALSE(ev.out_of_order);
}

TEST(FrameMatcher, TooManyPendingDecidesTheOldest) {
  Matcher::Params p;
  p.max_pending = 2;
  Matcher m(p);
  const ros::Time now(100.0);
  m.addSweep(ros::Time(9.99), 1, now);
  m.addImages(ros::Time(10.0), 100, now);
  m.addImages(ros::Time(10.1), 101, now);
  auto ev = m.addImages(ros::Time(10.2), 102, now);
  ASSERT_EQ(ev.ready.size(), 1u);
  EXPECT_EQ(ev.ready[0].images, 100);
  EXPECT_EQ(m.pendingCount(), 2u);
}

TEST(FrameMatcher, SeveralReadyAtOnceOldestFirst) {
  Matcher m;
  const ros::Time now(100.0);
  m.addImages(ros::Time(10.0), 100, now);
  m.addImages(ros::Time(10.05), 101, now);
  auto ev = m.addSweep(ros::Time(10.06), 1, now);
  ASSERT_EQ(ev.ready.size(), 2u);
  EXPECT_EQ(ev.ready[0].images, 100);
  EXPECT_EQ(ev.ready[1].images, 101);
}
