// rostest (test/ros/kitti_bag_rates.test, /use_sim_time true): the result must not depend on the
// playback rate (issue 9, point 4). Three KITTI frames 2.5 s apart go through kitti_to_bag; the bag
// is played with `rosbag play --clock` at -r 0.1, -r 0.5 and real time (each copy shifted 1000 s
// later, so that time only moves forward) into the fusion nodelet of launch/fusion.launch.
// Every published depth must equal the core pipeline's offline depth for that frame (the same
// comparison as test_kitti_bag: the same pixels, values within 1e-6 relative), so no frame was
// paired with another frame's sweep; at -r 0.1 every frame, the first included, must come out.
// The confidence output is checked beside the depth: 32FC1 in [0, 1], the size of the image, in the
// depth's frame.
// Missing data fails under CI=true and skips otherwise.
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <cv_bridge/cv_bridge.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_msgs/TFMessage.h>

#include "child_process.h"
#include "data/data_guard.h"
#include "kitti_bag_expected.h"
#include "kitti_bag_util.h"
#include "lidar_stereo_fusion/FusionStats.h"
#include "lidar_stereo_fusion/io/kitti.h"

namespace fs = std::filesystem;
namespace kitti = lidar_stereo_fusion::kitti;
namespace lt = lidar_stereo_fusion::test;

namespace {

const std::vector<std::string> kFrames = {"0000000000", "0000000025", "0000000050"};

/// Copy of `in` with every header stamp and message time moved by `shift` (the static TF too).
void writeShiftedBag(const std::string& in, const std::string& out, const ros::Duration& shift) {
  rosbag::Bag src(in, rosbag::bagmode::Read), dst(out, rosbag::bagmode::Write);
  for (const rosbag::MessageInstance& m : rosbag::View(src)) {
    const ros::Time t = m.getTime() + shift;
    const auto& header = m.getConnectionHeader();
    if (auto image = m.instantiate<sensor_msgs::Image>()) {
      image->header.stamp += shift;
      dst.write(m.getTopic(), t, image, header);
    } else if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
      info->header.stamp += shift;
      dst.write(m.getTopic(), t, info, header);
    } else if (auto cloud = m.instantiate<sensor_msgs::PointCloud2>()) {
      cloud->header.stamp += shift;
      dst.write(m.getTopic(), t, cloud, header);
    } else if (auto tf = m.instantiate<tf2_msgs::TFMessage>()) {
      for (auto& transform : tf->transforms) transform.header.stamp += shift;
      dst.write(m.getTopic(), t, tf, header);
    }
  }
}

/// Depth and confidence images received, keyed by stamp, and the node's count of processed frames
/// at each stamp (FusionStats::processed_frames).
struct Collector {
  std::mutex mutex;
  std::condition_variable cv;
  std::map<ros::Time, std::vector<sensor_msgs::ImageConstPtr>> depth, confidence;
  std::map<ros::Time, uint32_t> processed;

  void addStats(const lidar_stereo_fusion::FusionStatsConstPtr& msg) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      processed[msg->header.stamp] = msg->processed_frames;
    }
    cv.notify_all();
  }
  /// Messages of `store` received in total.
  static std::size_t count(
      const std::map<ros::Time, std::vector<sensor_msgs::ImageConstPtr>>& store) {
    std::size_t n = 0;
    for (const auto& [stamp, msgs] : store) n += msgs.size();
    return n;
  }

  void add(std::map<ros::Time, std::vector<sensor_msgs::ImageConstPtr>>& store,
           const sensor_msgs::ImageConstPtr& msg) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      store[msg->header.stamp].push_back(msg);
    }
    cv.notify_all();
  }
};

/// Number of pixels where `z` (NaN = none) and `expected` (0 = none) differ in having a value or
/// by more than 1e-6 relative.
int differingPixels(const cv::Mat1f& z, const cv::Mat1f& expected) {
  int differ = 0;
  for (int y = 0; y < z.rows; ++y) {
    for (int x = 0; x < z.cols; ++x) {
      const float v = z(y, x), e = expected(y, x);
      const bool has = std::isfinite(v) && v > 0, has_expected = e > 0;
      if (has != has_expected || (has && !(std::abs(v - e) <= 1e-6f * e))) ++differ;
    }
  }
  return differ;
}

}  // namespace

TEST(KittiBagRates, EveryPublishedDepthIsItsOwnFramesAtAnyPlaybackRate) {
  LSF_REQUIRE_DATA(std::string(lt::kKittiDate) + "/" + lt::kKittiDrive);
  ASSERT_TRUE(ros::Time::isSimTime()) << "kitti_bag_rates.test sets /use_sim_time";
  const std::string scratch = lt::scratchDir("test_kitti_bag_rates");
  const std::string drive = lt::makeSubsetDrive(scratch, kFrames);
  const std::string bag_path = scratch + "/frames.bag";
  fs::remove(bag_path);
  const auto [status, output] = lt::runCommand(std::string(LSF_KITTI_TO_BAG) + " --kitti-raw " +
                                               drive + " --out " + bag_path);
  ASSERT_EQ(status, 0) << output;

  // The offline answer of every frame: the nodelet's parameter file, the transform of the bag.
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  std::vector<ros::Time> stamps;
  tf2_msgs::TFMessageConstPtr tf_static;
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (m.getTopic() == "/stereo/left/image_rect_color") {
      stamps.push_back(m.instantiate<sensor_msgs::Image>()->header.stamp);
    } else if (m.getTopic() == "/tf_static") {
      tf_static = m.instantiate<tf2_msgs::TFMessage>();
    }
  }
  bag.close();
  ASSERT_EQ(stamps.size(), kFrames.size());
  ASSERT_TRUE(tf_static);
  const std::string params_yaml = std::string(LSF_SOURCE_DIR) + "/config/fusion.yaml";
  const kitti::Calibration calib = kitti::readCalibration(kitti::calibrationDirOf(drive));
  const std::vector<kitti::Frame> frames = kitti::listFrames(drive);
  ASSERT_EQ(frames.size(), kFrames.size());
  const Eigen::Isometry3d T_cam_velo = tf2::transformToEigen(tf_static->transforms.at(0)).inverse();
  std::vector<cv::Mat1f> expected;
  for (const auto& frame : frames) {
    expected.push_back(lt::expectedDepth(params_yaml, frame, calib, T_cam_velo));
  }

  ros::NodeHandle nh("fusion");
  Collector got;
  auto depth_sub = nh.subscribe<sensor_msgs::Image>(
      "depth/image_rect", 10, [&](const sensor_msgs::ImageConstPtr& m) { got.add(got.depth, m); });
  auto confidence_sub = nh.subscribe<sensor_msgs::Image>(
      "confidence", 10, [&](const sensor_msgs::ImageConstPtr& m) { got.add(got.confidence, m); });
  auto stats_sub = nh.subscribe<lidar_stereo_fusion::FusionStats>(
      "stats", 10, [&](const lidar_stereo_fusion::FusionStatsConstPtr& m) { got.addStats(m); });
  // Connected before the first frame: every processed frame's outputs reach the collector.
  ASSERT_TRUE(lt::waitFor(30.0, [&] {
    return depth_sub.getNumPublishers() > 0 && confidence_sub.getNumPublishers() > 0 &&
           stats_sub.getNumPublishers() > 0;
  })) << "the fusion's outputs are not advertised";

  const std::vector<double> rates = {0.1, 0.5, 1.0};
  for (size_t r = 0; r < rates.size(); ++r) {
    const double rate = rates[r];
    SCOPED_TRACE("rosbag play -r " + std::to_string(rate));
    const ros::Duration shift(1000.0 * static_cast<double>(r));
    const std::string shifted = scratch + "/shifted_" + std::to_string(r) + ".bag";
    writeShiftedBag(bag_path, shifted, shift);
    // --wait-for-subscribers: the first message only once the nodelet (subscribed lazily via our
    // subscribers) has connected to every topic of the bag.
    const auto [play_status, play_output] =
        lt::runCommand("timeout 300 rosbag play --clock -q --wait-for-subscribers -r " +
                       std::to_string(rate) + " " + shifted);
    ASSERT_EQ(play_status, 0) << play_output;
    fs::remove(shifted);
    // The last set is decided when its sweep arrives (the bag's last message); wait for the
    // worker to publish it, and for the depth and confidence of every frame the node says it
    // processed (its stats of that set) to have arrived here: then no output of this bag is still
    // on its way.
    const ros::Time last = stamps.back() + shift;
    std::unique_lock<std::mutex> lock(got.mutex);
    const bool all_arrived = got.cv.wait_for(lock, std::chrono::seconds(120), [&] {
      return got.processed.count(last) > 0 && got.count(got.depth) >= got.processed.at(last) &&
             got.count(got.confidence) >= got.processed.at(last);
    });
    ASSERT_TRUE(all_arrived) << "the stats of the last frame, or the depth or confidence of a "
                             << "processed frame, did not arrive";
    EXPECT_EQ(got.count(got.depth), got.processed.at(last)) << "a depth without a frame";
    EXPECT_EQ(got.count(got.confidence), got.processed.at(last)) << "a confidence without a frame";
    int published = 0;
    for (size_t i = 0; i < stamps.size(); ++i) {
      const ros::Time t = stamps[i] + shift;
      const auto it = got.depth.find(t);
      if (it == got.depth.end()) {
        EXPECT_NE(rate, 0.1) << "frame " << kFrames[i] << " lost at -r 0.1";
        continue;
      }
      ++published;
      ASSERT_EQ(it->second.size(), 1u) << "frame " << kFrames[i] << " published twice";
      const cv::Mat1f z = cv_bridge::toCvShare(it->second.front())->image;
      ASSERT_EQ(z.size(), expected[i].size());
      EXPECT_EQ(differingPixels(z, expected[i]), 0)
          << "frame " << kFrames[i] << ": the depth is not the offline one (wrong sweep?)";
      const auto ct = got.confidence.find(t);
      ASSERT_NE(ct, got.confidence.end()) << "no confidence for frame " << kFrames[i];
      const auto& c = ct->second.front();
      EXPECT_EQ(c->encoding, "32FC1");
      EXPECT_EQ(c->header.frame_id, it->second.front()->header.frame_id);
      const cv::Mat1f confidence = cv_bridge::toCvShare(c)->image;
      ASSERT_EQ(confidence.size(), z.size());
      double lo = 0, hi = 0;
      cv::minMaxLoc(confidence, &lo, &hi);
      EXPECT_GE(lo, 0.0);
      EXPECT_LE(hi, 1.0);
    }
    std::printf(
        "rosbag play -r %.1f: %d of %zu frames published, each equal to the offline depth\n", rate,
        published, stamps.size());
    EXPECT_GT(published, 0);
  }
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_kitti_bag_rates");
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(2);
  spinner.start();
  return RUN_ALL_TESTS();
}
