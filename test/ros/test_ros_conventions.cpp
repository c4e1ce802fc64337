// rostest (test/ros/ros_conventions.test): the outputs follow the conventions of depth_image_proc
// and stereo_image_proc closely enough that their nodelets consume them by remapping alone, and
// the parameters behave as a ROS user expects (issue 10):
//   * points2 is organised like the depth image: its point (u, v) is depth pixel (u, v)
//     back-projected with depth/camera_info, NaN where the depth has none (so the same range);
//   * depth_image_proc/point_cloud_xyz, fed depth/image_rect + depth/camera_info by remapping only,
//     gives the same cloud as points2;
//   * stereo_image_proc/point_cloud2 takes either stereo_image_proc/disparity's output or ours by
//     remapping only, and gives from ours the points of points2; our DisparityImage carries the
//     configured search range as stereo_image_proc's does;
//   * `dynparam set` of a misspelled name is refused by dynparam, of an invalid value by the node,
//     which logs why, and `dynparam get` then shows the value in force; one spelling per
//     parameter on the parameter server;
//   * an input topic that publishes nothing is named in a warning.
#include <cmath>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <stereo_msgs/DisparityImage.h>

#include "child_process.h"
#include "fusion_test_harness.h"
#include "lidar_stereo_fusion/core/patchmatch.h"
#include "run_command.h"

using namespace fusion_test;  // NOLINT: the harness of these tests
namespace lt = lidar_stereo_fusion::test;

namespace {

std::unique_ptr<Harness> harness;

/// Latest message on a topic, with its stamp.
template <class M>
struct Latest {
  std::mutex mutex;
  std::map<uint64_t, boost::shared_ptr<const M>> by_stamp;
  ros::Subscriber sub;
  void subscribe(ros::NodeHandle& nh, const std::string& topic) {
    sub = nh.subscribe<M>(topic, 5, [this](const boost::shared_ptr<const M>& m) {
      std::lock_guard<std::mutex> lock(mutex);
      by_stamp[m->header.stamp.toNSec()] = m;
    });
  }
  std::size_t size() {
    std::lock_guard<std::mutex> lock(mutex);
    return by_stamp.size();
  }
  bool has(const ros::Time& stamp) {
    std::lock_guard<std::mutex> lock(mutex);
    return by_stamp.count(stamp.toNSec()) > 0;
  }
  boost::shared_ptr<const M> at(const ros::Time& stamp, double timeout = kOutputTimeout) {
    boost::shared_ptr<const M> out;
    Harness::waitFor(timeout, [&] {
      std::lock_guard<std::mutex> lock(mutex);
      const auto it = by_stamp.find(stamp.toNSec());
      if (it != by_stamp.end()) out = it->second;
      return static_cast<bool>(out);
    });
    return out;
  }
};

/// x, y, z of point i of an organised cloud.
cv::Vec3f pointAt(const sensor_msgs::PointCloud2& cloud, std::size_t i) {
  cv::Vec3f p;
  for (int k = 0; k < 3; ++k) {
    const auto& f = cloud.fields[k];
    std::memcpy(&p[k], &cloud.data[i * cloud.point_step + f.offset], 4);
  }
  return p;
}

/// Index of field `name` in the cloud's field list, which must start with x, y, z.
void expectXyzFirst(const sensor_msgs::PointCloud2& cloud) {
  ASSERT_GE(cloud.fields.size(), 3u);
  EXPECT_EQ(cloud.fields[0].name, "x");
  EXPECT_EQ(cloud.fields[1].name, "y");
  EXPECT_EQ(cloud.fields[2].name, "z");
}

/// Number of pixels where the two organised clouds differ: one has a finite point and the other
/// not, or the points are further apart than 1e-4 of the depth (+ 1 mm).
int differingPoints(const sensor_msgs::PointCloud2& a, const sensor_msgs::PointCloud2& b,
                    int* both_finite) {
  int differ = 0;
  *both_finite = 0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(a.width) * a.height; ++i) {
    const cv::Vec3f p = pointAt(a, i), q = pointAt(b, i);
    const bool fp = std::isfinite(p[2]), fq = std::isfinite(q[2]);
    if (fp != fq) {
      ++differ;
    } else if (fp) {
      ++*both_finite;
      if (cv::norm(p - q) > 1e-4 * std::abs(p[2]) + 1e-3) ++differ;
    }
  }
  return differ;
}

/// The node of the image_pipeline nodelets (ros_conventions.test's manager).
constexpr const char* kImageProcManager = "/image_proc_manager";

/// Each test starts from the node's idle state, whatever ran before: no output subscriber of an
/// earlier test, so the inputs are unsubscribed (and the silent-input watch restarts when a test
/// subscribes).
class RosConventions : public ::testing::Test {
 protected:
  void SetUp() override {
    h().unsubscribeOutputs();
    h().forgetLatestOutputs();
    ASSERT_TRUE(h().inputsSubscribed(false, 10.0))
        << "inputs subscribed without output subscribers";
  }
  void TearDown() override { h().unsubscribeOutputs(); }
  Harness& h() { return *harness; }

  /// Publishes input sets, one every `period` seconds, until `arrived(stamp)` holds for the stamp
  /// of one of them (a consumer that subscribes lazily may miss the first sets); waits at most
  /// `timeout` [s]. Returns that stamp, or ros::Time() when none arrived.
  ros::Time publishUntil(const std::function<bool(const ros::Time&)>& arrived,
                         double timeout = 2 * kOutputTimeout, double period = 3.0) {
    std::vector<ros::Time> sent;
    ros::Time found;
    const auto any_arrived = [&] {
      for (const ros::Time& stamp : sent) {
        if (arrived(stamp)) {
          found = stamp;
          return true;
        }
      }
      return false;
    };
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
    while (ros::WallTime::now() < end) {
      sent.push_back(h().nextStamp());
      h().publishSet(SetSpec(), sent.back());
      if (Harness::waitFor(period, any_arrived)) return found;
    }
    return ros::Time();
  }

  ros::NodeHandle nh_;
};

}  // namespace

// The inputs are subscribed for an output subscriber, the images come, the LiDAR does not; after
// ~input_timeout (2 s in the .test) a warning names the silent topic (the watch starts anew with
// each subscription of the inputs: the fixture's start has none).
TEST_F(RosConventions, SilentInputTopicIsNamed) {
  const std::size_t mark = h().logMark();
  h().subscribeOutputs({"stats"});
  ASSERT_TRUE(h().inputsSubscribed(true, 10.0));
  SetSpec images_only;
  images_only.cloud = SetSpec::Cloud::kNone;
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(15.0);
  bool named = false;
  while (ros::WallTime::now() < end && !named) {
    h().publishSet(images_only, h().nextStamp());
    named = h().waitForLog(mark, {"/velodyne_points", "nothing received"}, 0.5);
  }
  EXPECT_TRUE(named) << h().logsSince(mark);
  for (const auto& w : h().warningsSince(mark)) {
    EXPECT_EQ(w.find("/stereo/left/image_rect_color: nothing received"), std::string::npos) << w;
  }
}

TEST_F(RosConventions, OrganisedCloudPixelIsTheDepthPixel) {
  h().subscribeOutputs({"depth/image_rect", "depth/camera_info", "points2", "disparity"});
  ASSERT_TRUE(h().outputsConnected());
  ASSERT_TRUE(h().inputsSubscribed(true, 10.0));
  const ros::Time stamp = h().nextStamp();
  h().publishSet(SetSpec(), stamp);
  ASSERT_TRUE(Harness::waitFor(kOutputTimeout, [&] {
    return h().count("points2", stamp) && h().count("depth/image_rect", stamp) &&
           h().count("depth/camera_info", stamp) && h().count("disparity", stamp);
  }));
  const auto depth = h().image("depth/image_rect");
  const auto info = h().depthInfo();
  const auto cloud = h().points();
  ASSERT_EQ(cloud->height, depth->height);
  ASSERT_EQ(cloud->width, depth->width);
  expectXyzFirst(*cloud);
  const double fx = info->K[0], fy = info->K[4], cx = info->K[2], cy = info->K[5];
  int with_depth = 0, wrong = 0;
  for (uint32_t v = 0; v < depth->height; ++v) {
    const float* row = reinterpret_cast<const float*>(&depth->data[v * depth->step]);
    for (uint32_t u = 0; u < depth->width; ++u) {
      const cv::Vec3f p = pointAt(*cloud, v * cloud->width + u);
      const float z = row[u];
      if (!std::isfinite(z)) {
        wrong += std::isfinite(p[2]);
        continue;
      }
      ++with_depth;
      const float x = static_cast<float>((u - cx) * z / fx),
                  y = static_cast<float>((v - cy) * z / fy);
      if (std::abs(p[2] - z) > 1e-5f * z || std::abs(p[0] - x) > 1e-4f * z ||
          std::abs(p[1] - y) > 1e-4f * z) {
        ++wrong;
      }
    }
  }
  EXPECT_GT(with_depth, static_cast<int>(depth->width * depth->height) / 2);
  EXPECT_EQ(wrong, 0) << "points2 (u, v) is not depth (u, v) back-projected";
  EXPECT_EQ(cloud->is_dense, with_depth == static_cast<int>(depth->width * depth->height))
      << "is_dense must be false when a point is NaN";

  // The DisparityImage's range is the configured search range (config/fusion.yaml: 1 .. 192 px).
  const auto disparity = h().disparity();
  EXPECT_FLOAT_EQ(disparity->min_disparity, 1.f);
  EXPECT_FLOAT_EQ(disparity->max_disparity, 192.f);
}

// depth_image_proc/point_cloud_xyz reads /fusion/depth/image_rect + /fusion/depth/camera_info
// (remapped in the .test, nothing else) and publishes /depth_image_proc/points.
TEST_F(RosConventions, DepthImageProcConsumesTheDepthByRemappingOnly) {
  h().subscribeOutputs({"points2"});
  Latest<sensor_msgs::PointCloud2> theirs, ours_by_stamp;
  theirs.subscribe(nh_, "/depth_image_proc/points");
  ours_by_stamp.subscribe(nh_, h().output("points2"));
  ASSERT_TRUE(h().outputsConnected());
  ASSERT_TRUE(Harness::waitFor(10.0, [&] { return theirs.sub.getNumPublishers() > 0; }));
  // point_cloud_xyz subscribes to the depth lazily, once it has a subscriber.
  ASSERT_TRUE(Harness::waitFor(10.0, [&] {
    return lt::hasSubscriber(h().output("depth/image_rect"), kImageProcManager) &&
           lt::hasSubscriber(h().output("depth/camera_info"), kImageProcManager);
  })) << "depth_image_proc/point_cloud_xyz does not subscribe to the depth";
  const ros::Time stamp = publishUntil([&](const ros::Time& t) { return theirs.has(t); });
  ASSERT_FALSE(stamp.isZero()) << "no cloud from depth_image_proc/point_cloud_xyz";
  const auto cloud = theirs.at(stamp);
  const auto ours = ours_by_stamp.at(stamp);
  ASSERT_TRUE(ours) << "no points2 stamped as depth_image_proc's cloud";
  ASSERT_EQ(cloud->width, ours->width);
  ASSERT_EQ(cloud->height, ours->height);
  EXPECT_EQ(cloud->header.frame_id, ours->header.frame_id);
  expectXyzFirst(*cloud);
  int both = 0;
  EXPECT_EQ(differingPoints(*cloud, *ours, &both), 0);
  EXPECT_GT(both, static_cast<int>(cloud->width * cloud->height) / 2);
}

// One launch file (ros_conventions.test) runs stereo_image_proc/point_cloud2 twice: /sip_cloud
// on stereo_image_proc/disparity's output, /ours_cloud on /fusion/disparity; the two differ only
// in a remap of `disparity`.
TEST_F(RosConventions, StereoImageProcDisparityAndOursSwapByRemappingOnly) {
  h().subscribeOutputs({"points2", "disparity"});
  Latest<stereo_msgs::DisparityImage> sip_disparity, ours_disparity;
  Latest<sensor_msgs::PointCloud2> sip_cloud, ours_cloud, ours_points;
  sip_disparity.subscribe(nh_, "/sip/disparity");
  sip_cloud.subscribe(nh_, "/sip_cloud/points2");
  ours_cloud.subscribe(nh_, "/ours_cloud/points2");
  ours_disparity.subscribe(nh_, h().output("disparity"));
  ours_points.subscribe(nh_, h().output("points2"));
  ASSERT_TRUE(h().outputsConnected());
  ASSERT_TRUE(Harness::waitFor(10.0, [&] {
    return sip_cloud.sub.getNumPublishers() > 0 && ours_cloud.sub.getNumPublishers() > 0 &&
           sip_disparity.sub.getNumPublishers() > 0;
  }));
  // The image_pipeline nodelets subscribe to their inputs lazily, once they have a subscriber.
  ASSERT_TRUE(Harness::waitFor(10.0, [&] {
    return lt::hasSubscriber(h().output("disparity"), kImageProcManager) &&
           lt::hasSubscriber("/sip/disparity", kImageProcManager) &&
           lt::hasSubscriber("/stereo/right/image_rect_color", kImageProcManager);
  })) << "the stereo_image_proc nodelets do not subscribe to their inputs";
  const ros::Time stamp =
      publishUntil([&](const ros::Time& t) { return ours_cloud.has(t) && sip_cloud.has(t); });
  ASSERT_FALSE(stamp.isZero()) << "stereo_image_proc/point_cloud2 did not give both clouds of a "
                               << "set (from our disparity: " << ours_cloud.size()
                               << ", from its own: " << sip_cloud.size() << ")";
  const auto from_ours = ours_cloud.at(stamp);
  const auto from_sip = sip_cloud.at(stamp);
  const auto theirs = sip_disparity.at(stamp);
  const auto ours = ours_disparity.at(stamp);
  const auto points = ours_points.at(stamp);
  ASSERT_TRUE(theirs && ours && points);
  EXPECT_EQ(ours->image.encoding, theirs->image.encoding);
  EXPECT_EQ(ours->image.width, theirs->image.width);
  EXPECT_EQ(ours->image.height, theirs->image.height);
  EXPECT_EQ(ours->header.frame_id, theirs->header.frame_id);
  EXPECT_NEAR(ours->f, theirs->f, 1e-3);
  EXPECT_NEAR(ours->T, theirs->T, 1e-6);
  EXPECT_LT(ours->min_disparity, ours->max_disparity);
  EXPECT_EQ(from_ours->width, from_sip->width);
  EXPECT_EQ(from_ours->height, from_sip->height);
  // stereo_image_proc's cloud from our disparity holds our points (where both have one).
  int both = 0, far = 0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(points->width) * points->height; ++i) {
    const cv::Vec3f p = pointAt(*points, i), q = pointAt(*from_ours, i);
    if (!std::isfinite(p[2]) || !std::isfinite(q[2])) continue;
    ++both;
    far += cv::norm(p - q) > 1e-3 * std::abs(p[2]) + 1e-3;
  }
  EXPECT_GT(both, static_cast<int>(points->width * points->height) / 2);
  EXPECT_EQ(far, 0);
}

/// `dynparam` of the system Python (a pyenv or conda python3 first on PATH cannot import rospy).
const char* const kDynparam = "/usr/bin/python3 /usr/lib/dynamic_reconfigure/dynparam";

/// Sets the node's window_radius back to its default when a test ends, however it ends.
struct RestoreWindowRadius {
  std::string node;
  ~RestoreWindowRadius() {
    lt::runCommand(std::string(kDynparam) + " set " + node + " window_radius " +
                   std::to_string(lidar_stereo_fusion::PatchMatchParams().window_radius));
  }
};

TEST_F(RosConventions, DynparamRefusalsAreVisibleAndTheValueInForceIsShown) {
  const std::string node = h().fusionNode();
  const std::string dynparam = kDynparam;
  const RestoreWindowRadius restore{node};
  const auto get = [&] { return lt::runCommand(dynparam + " get " + node).second; };
  const std::string window =
      "'window_radius': " + std::to_string(lidar_stereo_fusion::PatchMatchParams().window_radius);
  ASSERT_NE(get().find(window), std::string::npos) << get();

  // A misspelled name: dynparam itself refuses it, naming it.
  auto [status, out] = lt::runCommand(dynparam + " set " + node + " window_radus 2");
  EXPECT_NE(out.find("don't know parameter: window_radus"), std::string::npos) << out;

  // An invalid value: the node refuses it, logs why, and the value in force stays.
  std::size_t mark = h().logMark();
  std::tie(status, out) = lt::runCommand(dynparam + " set " + node + " window_radius 0");
  EXPECT_TRUE(h().waitForLog(
      mark, {"refused", "window_radius must be in [1, 50]", "window_radius = 0 (in force: "}))
      << out << h().logsSince(mark);
  EXPECT_NE(get().find(window), std::string::npos) << get();

  mark = h().logMark();
  std::tie(status, out) = lt::runCommand(dynparam + " set " + node + " method bogus");
  EXPECT_TRUE(h().waitForLog(mark, {"refused", "method = bogus (in force: fused_bi)"}))
      << out << h().logsSince(mark);
  EXPECT_NE(get().find("'method': 'fused_bi'"), std::string::npos) << get();

  // A valid value under the one name: applied, on the server under that name only.
  std::tie(status, out) = lt::runCommand(dynparam + " set " + node + " window_radius 6");
  EXPECT_EQ(status, 0) << out;
  EXPECT_NE(get().find("'window_radius': 6"), std::string::npos) << get();
  int radius = 0;
  EXPECT_TRUE(ros::param::get(node + "/window_radius", radius));
  EXPECT_EQ(radius, 6);
  std::vector<std::string> names;
  ASSERT_TRUE(ros::param::getParamNames(names));
  for (const auto& name : names) {
    if (name.rfind(node + "/", 0) != 0) continue;
    EXPECT_EQ(name.find("patchmatch"), std::string::npos) << name << ": a second spelling";
  }
}

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_ros_conventions");
  ros::AsyncSpinner spinner(3);
  spinner.start();
  harness = std::make_unique<Harness>();
  const int result = RUN_ALL_TESTS();
  harness.reset();
  spinner.stop();
  ros::shutdown();
  return result;
}
