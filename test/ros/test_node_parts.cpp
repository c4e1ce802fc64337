// Unit tests of the three parts of the live node without a ROS master: the input gate's checks and
// rate limit, the throttled log, and the output publisher's latency and FusionStats.
#include <string>

#include <gtest/gtest.h>

#include <sensor_msgs/point_cloud2_iterator.h>
#include <boost/make_shared.hpp>

#include "lidar_stereo_fusion/ros/conversions.h"
#include "lidar_stereo_fusion/ros/fresh_wait.h"
#include "lidar_stereo_fusion/ros/input_gate.h"
#include "lidar_stereo_fusion/ros/input_watch.h"
#include "lidar_stereo_fusion/ros/node_support.h"
#include "lidar_stereo_fusion/ros/output_publisher.h"

namespace lsf = lidar_stereo_fusion;

namespace {

sensor_msgs::ImagePtr image(uint32_t width, const std::string& encoding = "bgr8") {
  auto msg = boost::make_shared<sensor_msgs::Image>();
  msg->header.frame_id = "left";
  msg->width = width;
  msg->height = 4;
  msg->encoding = encoding;
  msg->step = width * 3;
  msg->data.assign(msg->step * msg->height, 100);
  return msg;
}

sensor_msgs::CameraInfoPtr info(uint32_t width, double tx) {
  auto msg = boost::make_shared<sensor_msgs::CameraInfo>();
  msg->width = width;
  msg->height = 4;
  msg->P = {700, 0, 4, tx, 0, 700, 2, 0, 0, 0, 1, 0};
  return msg;
}

lsf::ImageSet goodSet() {
  lsf::ImageSet set;
  set.left = image(8);
  set.right = image(8);
  set.left_info = info(8, 0);
  set.right_info = info(8, -700 * 0.12);  // ZED: 12 cm
  return set;
}

}  // namespace

TEST(InputGate, ImageSetChecksNameTopicAndKind) {
  EXPECT_FALSE(lsf::checkImageSet(goodSet()));

  lsf::ImageSet set = goodSet();
  set.left = image(8, "16UC1");
  auto r = lsf::checkImageSet(set);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->topic, lsf::kLeftImage);
  EXPECT_EQ(r->kind, "image");
  EXPECT_NE(r->problem.find("16UC1"), std::string::npos);

  set = goodSet();
  set.right = image(6);
  r = lsf::checkImageSet(set);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->topic, lsf::kRightImage);
  EXPECT_EQ(r->kind, "size");

  set = goodSet();
  set.left_info = info(6, 0);
  r = lsf::checkImageSet(set);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->topic, lsf::kLeftInfo);

  set = goodSet();
  set.right_info = info(8, -700 * 120.0);  // P[3] in millimetres
  r = lsf::checkImageSet(set);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->topic, lsf::kRightInfo);
  EXPECT_EQ(r->kind, "calibration");
  EXPECT_NE(r->problem.find("millimetres"), std::string::npos) << r->problem;

  set = goodSet();
  auto no_frame = boost::make_shared<sensor_msgs::Image>(*set.left);
  no_frame->header.frame_id.clear();
  set.left = no_frame;
  r = lsf::checkImageSet(set);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->kind, "frame_id");
}

TEST(InputGate, CloudChecksNameTheKind) {
  lsf::LidarCloud points(3);
  std_msgs::Header header;
  header.frame_id = "velodyne";
  sensor_msgs::PointCloud2 cloud = lsf::conversions::cloudToMsg(points, header);
  EXPECT_FALSE(lsf::checkCloud(cloud));
  sensor_msgs::PointCloud2 truncated = cloud;
  truncated.data.pop_back();
  EXPECT_EQ(lsf::checkCloud(truncated)->kind, "layout");
  sensor_msgs::PointCloud2 empty = lsf::conversions::cloudToMsg({}, header);
  EXPECT_EQ(lsf::checkCloud(empty)->kind, "empty");
  sensor_msgs::PointCloud2 no_frame = cloud;
  no_frame.header.frame_id.clear();
  EXPECT_EQ(lsf::checkCloud(no_frame)->kind, "frame_id");
}

TEST(InputGate, RateLimiterKeepsOneSetPerPeriod) {
  lsf::RateLimiter five_hz(5.0);
  int accepted = 0;
  for (int i = 0; i < 20; ++i) accepted += five_hz.accept(ros::Time(100.0 + 0.1 * i));  // 10 Hz
  EXPECT_EQ(accepted, 10);
  EXPECT_TRUE(five_hz.accept(ros::Time(50.0))) << "time went back (a bag loop): not throttled";
  lsf::RateLimiter unlimited(0.0);
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(unlimited.accept(ros::Time(100.0 + 0.01 * i)));
}

namespace {

/// Sets ready at 10 Hz from t = 100 s: `n` of them; returns the last one's time.
ros::Time readyAt10Hz(lsf::FreshWait& fresh, int n) {
  ros::Time t;
  for (int i = 0; i < n; ++i) fresh.ready(t = ros::Time(100.0 + 0.1 * i));
  return t;
}

ros::Time after(const ros::Time& t, double s) { return t + ros::Duration(s); }

}  // namespace

// ~fresh_wait: a set that waited for the busy worker is exchanged for the next one only when that
// is due within the wait; then the worker waits until the due time plus half the wait.
TEST(FreshWait, HoldsAWaitingSetOnlyWhenTheNextIsDueWithinTheWait) {
  lsf::FreshWait fresh(0.05);
  EXPECT_FALSE(fresh.holdUntil(ros::Time(100.09))) << "no period known yet";
  ros::Time last = readyAt10Hz(fresh, 3);  // two intervals: not yet a period
  EXPECT_EQ(fresh.period(), 0.0);
  EXPECT_FALSE(fresh.holdUntil(after(last, 0.09)));
  last = readyAt10Hz(fresh, 4);
  EXPECT_NEAR(fresh.period(), 0.1, 1e-9);
  const auto until = fresh.holdUntil(after(last, 0.06));  // next due in 40 ms
  ASSERT_TRUE(until);
  EXPECT_NEAR(until->toSec(), after(last, 0.125).toSec(), 1e-9);
  EXPECT_FALSE(fresh.holdUntil(after(last, 0.04))) << "next due in 60 ms";
  EXPECT_FALSE(fresh.holdUntil(last)) << "a fresh set";
  EXPECT_FALSE(fresh.holdUntil(after(last, 0.11))) << "the next is overdue";
}

TEST(FreshWait, WaitsAtMostHalfThePeriodAndZeroIsOff) {
  lsf::FreshWait greedy(1.0);
  ros::Time last = readyAt10Hz(greedy, 6);
  EXPECT_FALSE(greedy.holdUntil(after(last, 0.04)))
      << "next due in 60 ms: the set is fresher than the average";
  const auto until = greedy.holdUntil(after(last, 0.06));
  ASSERT_TRUE(until);
  EXPECT_NEAR(until->toSec(), after(last, 0.125).toSec(), 1e-9);
  lsf::FreshWait off(0.0);
  last = readyAt10Hz(off, 6);
  EXPECT_FALSE(off.holdUntil(after(last, 0.09)));
}

TEST(FreshWait, PeriodIsTheMedianIntervalAndRestartsWhenTimeGoesBack) {
  lsf::FreshWait fresh(0.05);
  for (const double t : {100.0, 100.1, 100.2, 100.7, 100.8}) fresh.ready(ros::Time(t));
  EXPECT_NEAR(fresh.period(), 0.1, 1e-9) << "one dropped sweep does not move the median";
  fresh.ready(ros::Time(100.8));  // two sets at once: no interval of 0
  EXPECT_NEAR(fresh.period(), 0.1, 1e-9);
  fresh.ready(ros::Time(50.0));  // a bag loop
  EXPECT_EQ(fresh.period(), 0.0);
  for (int i = 1; i <= static_cast<int>(lsf::FreshWait::kIntervals) + 5; ++i) {
    fresh.ready(ros::Time(50.0 + 0.2 * i));
  }
  EXPECT_NEAR(fresh.period(), 0.2, 1e-9);
}

TEST(ThrottledLog, OncePerPeriodPerTopicAndKindWithABoundedKeySet) {
  lsf::ThrottledLog log("test", 5.0);
  const ros::WallTime t0(1000.0);
  EXPECT_TRUE(log.shouldLog("velodyne_points", "layout", t0));
  EXPECT_FALSE(log.shouldLog("velodyne_points", "layout", t0 + ros::WallDuration(1.0)))
      << "a message whose text varies is still the same kind";
  EXPECT_TRUE(log.shouldLog("velodyne_points", "empty", t0 + ros::WallDuration(1.0)))
      << "another kind is not hidden";
  EXPECT_TRUE(log.shouldLog("left/image_rect_color", "layout", t0 + ros::WallDuration(1.0)));
  EXPECT_TRUE(log.shouldLog("velodyne_points", "layout", t0 + ros::WallDuration(5.1)));
  for (int i = 0; i < 1000; ++i) log.shouldLog("topic" + std::to_string(i), "kind", t0);
  EXPECT_LE(log.keys(), lsf::ThrottledLog::kMaxKeys);
}

// Issue 10, point 4: an input topic that sends nothing is named; one that went quiet once.
TEST(InputWatch, NamesSilentTopicsAfterTheTimeout) {
  lsf::ThrottledLog log("test", 0.0);
  lsf::InputWatch watch({"/a", "/b"}, 2.0, log);
  using Clock = lsf::InputWatch::Clock;
  const Clock::time_point t0 = Clock::now();
  const auto at = [&](double s) {
    return t0 + std::chrono::milliseconds(static_cast<int>(s * 1e3));
  };
  const auto none = [](std::size_t) { return 0u; };
  EXPECT_TRUE(watch.check(none, at(10)).empty()) << "not watching before start()";
  watch.start(at(0));
  watch.heard(0, at(0.5));
  EXPECT_TRUE(watch.check(none, at(1.9)).empty());
  EXPECT_EQ(watch.check(none, at(2.1)), (std::vector<std::size_t>{1}));     // /b never sent
  EXPECT_EQ(watch.check(none, at(2.6)), (std::vector<std::size_t>{0, 1}));  // /a quiet for 2.1 s
  watch.heard(0, at(3.0));
  watch.heard(1, at(3.0));
  EXPECT_TRUE(watch.check(none, at(4.0)).empty());
  watch.stop();
  EXPECT_TRUE(watch.check(none, at(60.0)).empty()) << "not watching after stop()";
}

TEST(OutputPublisher, LatencyNeverGoesNegativeAfterABagLoop) {
  // Normal: publish time - stamp in ROS time.
  EXPECT_NEAR(lsf::latencyMs(ros::Time(10.5), ros::Time(10.0), ros::Time(10.1), 400.0, false),
              500.0, 1e-6);
  // The bag looped while the frame was processed: ROS time is now before the arrival.
  const double loop =
      lsf::latencyMs(ros::Time(1.2), ros::Time(10.0), ros::Time(10.1), 400.0, false);
  EXPECT_NEAR(loop, 100.0 + 400.0, 1e-6);
  // ... or looped and came past the arrival again (a short bag at -r 5): the gate saw the restart.
  EXPECT_NEAR(lsf::latencyMs(ros::Time(10.9), ros::Time(10.0), ros::Time(10.1), 400.0, true), 500.0,
              1e-6);  // ... or the set of the loop's last frame arrived after the clock had gone
                      // back (seen live at
  // -r 5: -3205 ms): its arrival is in the new loop, its stamp in the old one.
  EXPECT_NEAR(lsf::latencyMs(ros::Time(6.0), ros::Time(10.0), ros::Time(5.0), 1900.0, true), 1900.0,
              1e-6);
}

TEST(OutputPublisher, StatsComeFromFrameStatsAndACounterSnapshot) {
  lsf::FrameStats s;
  s.projection_ms = 1;
  s.upsampling_ms = 2;
  s.patchmatch_ms = 3;
  s.depth_ms = 4;
  s.total_ms = 10;
  s.points_in_front = 100;
  s.points_projected = 90;
  s.points_removed = 7;
  s.prior_coverage = 0.25;
  s.output_coverage = 0.75;
  lsf::FrameReport report;
  report.method = "fused_bi";
  report.cloud_points = 120;
  report.rings.source = lsf::RingSource::kSweepOrder;
  report.rings.rings = 64;
  lsf::CounterSnapshot c;
  c.processed = 5;
  c.dropped = 1;
  c.unmatched = 2;
  c.tf_failures = 3;
  c.invalid = 4;
  c.out_of_order = 6;
  c.errors = 7;
  c.rate_limited = 8;
  std_msgs::Header header;
  header.frame_id = "left";
  const auto msg = lsf::makeStatsMsg(header, s, report, 2.5, 300.0, 0.03, c);
  EXPECT_EQ(msg->header.frame_id, "left");
  EXPECT_EQ(msg->method, "fused_bi");
  EXPECT_FLOAT_EQ(msg->patchmatch_ms, 3.f);
  EXPECT_FLOAT_EQ(msg->total_ms, 10.f);
  EXPECT_FLOAT_EQ(msg->conversion_ms, 2.5f);
  EXPECT_FLOAT_EQ(msg->latency_ms, 300.f);
  EXPECT_FLOAT_EQ(msg->sweep_time_offset, 0.03f);
  EXPECT_EQ(msg->points_in_cloud, 120);
  EXPECT_EQ(msg->points_removed, 7);
  EXPECT_EQ(msg->rings, 64);
  EXPECT_TRUE(msg->rings_recovered);
  EXPECT_EQ(msg->ring_method, "sweep_order");
  EXPECT_TRUE(msg->rings_plausible);
  EXPECT_FLOAT_EQ(msg->output_coverage, 0.75f);
  EXPECT_EQ(msg->processed_frames, 5u);
  EXPECT_EQ(msg->out_of_order, 6u);
  EXPECT_EQ(msg->processing_errors, 7u);
  EXPECT_EQ(msg->rate_limited, 8u);
  EXPECT_EQ(c.problems(), 1u + 2 + 3 + 4 + 6 + 7);
}
