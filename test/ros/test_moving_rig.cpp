// rostest (moving_rig.test): the moving synthetic rig (20 m/s, the LiDAR facing ahead 50 ms after
// the images, sweeps stamped at their end, per-point time) written to a bag with its ego-motion on
// /tf (odom -> left camera) and played frame by frame into two fusion nodelets: /moving_comp with
// ~fixed_frame: odom and /moving_raw without. The compensated depth is checked against the exact
// depth at the image instant and against the offline compensation of the same frame
// (core/motion_compensation.h); the uncompensated one shows what the motion costs.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <cv_bridge/cv_bridge.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <rosgraph_msgs/Log.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_msgs/TFMessage.h>

#include <opencv2/imgcodecs.hpp>

#include "child_process.h"
#include "lidar_stereo_fusion/FusionStats.h"
#include "lidar_stereo_fusion/core/metrics.h"
#include "lidar_stereo_fusion/sim/moving_rig.h"
#include "run_command.h"
#include "synthetic_input.h"

namespace lsf = lidar_stereo_fusion;
using lsf::test::kCameraFrame;
using lsf::test::kLidarFrame;
using lsf::test::kRightCameraFrame;

namespace {

constexpr int kFrames = 3;
constexpr double kSpacing = 0.5;  ///< [s] between the image stamps of consecutive frames in the bag

lsf::sim::SyntheticParams rigParams() {
  lsf::sim::SyntheticParams p = lsf::sim::SyntheticParams().resized(621, 188);
  p.azimuth_step_deg = 0.18;
  p.speed = 20.0;
  p.moving_sweep = true;
  p.lidar_time_offset = 0.05;
  return p;
}

/// Writes the bag: per frame the ego-motion (odom -> left camera every 10 ms from 0.15 s before
/// the images to 0.1 s after the sweep's end), the stereo pair and the sweep; /tf_static once.
void writeBag(const std::string& path, const std::vector<lsf::sim::SyntheticFrame>& frames,
              const lsf::sim::SyntheticParams& p, const ros::Time& base) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  tf2_msgs::TFMessage statics;
  statics.transforms.push_back(
      lsf::test::lidarToCameraTf(frames[0].T_cam_lidar, kCameraFrame, kLidarFrame));
  statics.transforms.back().header.stamp = base;
  bag.write("/tf_static", base, statics);
  for (int k = 0; k < kFrames; ++k) {
    const auto& f = frames[k];
    const ros::Time image = base + ros::Duration(0.2 + k * kSpacing);
    const ros::Time sweep = image + ros::Duration(f.cloud_stamp - f.stamp);
    for (double dt = -0.15; dt <= (sweep - image).toSec() + 0.1; dt += 0.01) {
      tf2_msgs::TFMessage tf;
      geometry_msgs::TransformStamped t = tf2::eigenToTransform(p.worldFromCamera(f.stamp + dt));
      t.header.frame_id = "odom";
      t.child_frame_id = kCameraFrame;
      t.header.stamp = image + ros::Duration(dt);
      tf.transforms.push_back(t);
      bag.write("/tf", t.header.stamp, tf);
    }
    bag.write("/stereo/left/camera_info", image,
              lsf::test::cameraInfoMsg(f.camera, false, kCameraFrame, image));
    bag.write("/stereo/right/camera_info", image,
              lsf::test::cameraInfoMsg(f.camera, true, kRightCameraFrame, image));
    bag.write("/stereo/left/image_rect_color", image,
              lsf::test::imageMsg(f.left, "bgr8", kCameraFrame, image));
    bag.write("/stereo/right/image_rect_color", image,
              lsf::test::imageMsg(f.right, "bgr8", kRightCameraFrame, image));
    bag.write("/velodyne_points", sweep, lsf::test::cloudMsg(f.cloud, kLidarFrame, sweep));
  }
}

/// Depth MAE [m] over the LiDAR's field of view where the output has a value, and that coverage.
std::pair<double, double> depthMae(const cv::Mat1f& depth, const lsf::sim::SyntheticFrame& f) {
  double sum = 0;
  int n = 0, total = 0;
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      if (!f.lidar_fov(v, u) || !(f.depth(v, u) > 0.f)) continue;
      ++total;
      if (!std::isfinite(depth(v, u)) || depth(v, u) <= 0.f) continue;
      sum += std::abs(depth(v, u) - f.depth(v, u));
      ++n;
    }
  }
  return {n > 0 ? sum / n : 1e9, total > 0 ? static_cast<double>(n) / total : 0.0};
}

class MovingRig : public ::testing::Test {
 protected:
  void depthCb(const std::string& ns, const sensor_msgs::ImageConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    depths_[ns][msg->header.stamp] = cv_bridge::toCvCopy(msg)->image;
  }
  void statsCb(const std::string& ns, const lidar_stereo_fusion::FusionStatsConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    stats_[ns][msg->header.stamp] = *msg;
  }
  void logCb(const rosgraph_msgs::LogConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    logs_.push_back(msg->msg);
  }
  bool logged(const std::string& a, const std::string& b) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& l : logs_) {
      if (l.find(a) != std::string::npos && l.find(b) != std::string::npos) return true;
    }
    return false;
  }
  bool have(const std::string& ns, const ros::Time& stamp) {
    std::lock_guard<std::mutex> lock(mutex_);
    return depths_[ns].count(stamp) > 0 && stats_[ns].count(stamp) > 0;
  }

  ros::NodeHandle nh_;
  std::mutex mutex_;
  std::map<std::string, std::map<ros::Time, cv::Mat1f>> depths_;
  std::map<std::string, std::map<ros::Time, lidar_stereo_fusion::FusionStats>> stats_;
  std::vector<std::string> logs_;
};

TEST_F(MovingRig, CompensatedDepthMatchesTheTruthAtTheImageInstant) {
  const lsf::sim::SyntheticParams p = rigParams();
  std::vector<lsf::sim::SyntheticFrame> frames;
  for (int k = 1; k <= kFrames; ++k) frames.push_back(lsf::sim::generateStreetFrame(p, k));
  const std::filesystem::path dir = std::filesystem::path(LSF_BINARY_DIR) / "moving_rig";
  std::filesystem::create_directories(dir);
  const std::string bag_path = (dir / "moving_rig.bag").string();
  const ros::Time base = ros::Time::now();
  writeBag(bag_path, frames, p, base);

  std::vector<ros::Subscriber> subs;
  ros::Subscriber rosout = nh_.subscribe<rosgraph_msgs::Log>(
      "/rosout", 100, [this](const rosgraph_msgs::LogConstPtr& m) { logCb(m); });
  for (const std::string ns : {"/moving_comp", "/moving_raw", "/moving_skip"}) {
    subs.push_back(nh_.subscribe<sensor_msgs::Image>(
        ns + "/depth/image_rect", 5,
        [this, ns](const sensor_msgs::ImageConstPtr& m) { depthCb(ns, m); }));
    subs.push_back(nh_.subscribe<lidar_stereo_fusion::FusionStats>(
        ns + "/stats", 5,
        [this, ns](const lidar_stereo_fusion::FusionStatsConstPtr& m) { statsCb(ns, m); }));
  }
  // Play the bag as rosbag play would, frame by frame: each frame's messages in bag order, then
  // wait for both nodelets' outputs of that frame.
  std::map<std::string, ros::Publisher> pubs;
  pubs["/tf_static"] = nh_.advertise<tf2_msgs::TFMessage>("/tf_static", 1, true);
  pubs["/tf"] = nh_.advertise<tf2_msgs::TFMessage>("/tf", 100);
  for (const char* t : {"/stereo/left/camera_info", "/stereo/right/camera_info"}) {
    pubs[t] = nh_.advertise<sensor_msgs::CameraInfo>(t, 5);
  }
  for (const char* t : {"/stereo/left/image_rect_color", "/stereo/right/image_rect_color"}) {
    pubs[t] = nh_.advertise<sensor_msgs::Image>(t, 5);
  }
  pubs["/velodyne_points"] = nh_.advertise<sensor_msgs::PointCloud2>("/velodyne_points", 5);
  ASSERT_TRUE(lsf::test::waitFor(30.0, [&] {
    for (auto& [topic, pub] : pubs) {
      if (topic != "/tf_static" && pub.getNumSubscribers() < 3) return false;
    }
    return true;
  })) << "the nodelets did not subscribe to the inputs and /tf";

  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  std::vector<ros::Time> image_stamps;
  for (const rosbag::MessageInstance& m : view) {
    const std::string topic = m.getTopic();
    if (topic == "/tf" || topic == "/tf_static") {
      pubs[topic].publish(m.instantiate<tf2_msgs::TFMessage>());
    } else if (topic.find("camera_info") != std::string::npos) {
      pubs[topic].publish(m.instantiate<sensor_msgs::CameraInfo>());
    } else if (topic.find("image_rect") != std::string::npos) {
      const auto image = m.instantiate<sensor_msgs::Image>();
      if (topic.find("left") != std::string::npos) image_stamps.push_back(image->header.stamp);
      pubs[topic].publish(image);
    } else if (topic == "/velodyne_points") {
      // The ego-motion up to the sweep's end went out before it; the worker waits for it on TF
      // up to ~tf_timeout (0.5 s in moving_rig.test).
      pubs[topic].publish(m.instantiate<sensor_msgs::PointCloud2>());
      const ros::Time stamp = image_stamps.back();
      EXPECT_TRUE(lsf::test::waitFor(60.0,
                                     [&] {
                                       return have("/moving_comp", stamp) &&
                                              have("/moving_raw", stamp) &&
                                              have("/moving_skip", stamp);
                                     }))
          << "no output for the frame at " << stamp;
    }
  }
  ASSERT_EQ(image_stamps.size(), static_cast<size_t>(kFrames));
  std::cerr << "played " << kFrames << " frames\n";

  for (int k = 0; k < kFrames; ++k) {
    const auto& f = frames[k];
    const ros::Time stamp = image_stamps[k];
    std::lock_guard<std::mutex> lock(mutex_);
    ASSERT_TRUE(depths_["/moving_comp"].count(stamp) && depths_["/moving_raw"].count(stamp));
    const auto& comp_stats = stats_["/moving_comp"][stamp];
    const auto& raw_stats = stats_["/moving_raw"][stamp];
    EXPECT_TRUE(comp_stats.motion_compensated) << k;
    EXPECT_FALSE(raw_stats.motion_compensated) << k;
    EXPECT_EQ(comp_stats.point_time_field, "time") << k;
    EXPECT_EQ(comp_stats.points_bad_time, 0) << k;
    EXPECT_EQ(comp_stats.motion_failures, 0u) << k;

    // The same compensation offline (the motion known exactly, sampled as the nodelet does).
    lsf::LidarCloud cloud = f.cloud;
    lsf::compensateMotion(cloud, lsf::sim::frameMotion(f, p));
    lsf::removePointsHiddenBeside(cloud, f.T_cam_lidar, f.camera);
    lsf::FusionInput input;
    input.left = f.left;
    input.right = f.right;
    input.cloud = cloud;
    input.T_cam_lidar = f.T_cam_lidar;
    input.camera = f.camera;
    lsf::FusionPipeline pipeline;
    const auto offline = depthMae(pipeline.process(input).depth, f);
    const auto comp = depthMae(depths_["/moving_comp"][stamp], f);
    const auto raw = depthMae(depths_["/moving_raw"][stamp], f);
    std::cerr << "frame " << k + 1 << ": depth MAE in the LiDAR's view, compensated " << comp.first
              << " m (offline " << offline.first << " m), uncompensated " << raw.first << " m\n";
    EXPECT_GT(comp.second, 0.95) << k;
    EXPECT_LT(comp.first, 1.1 * offline.first + 0.01) << k;
    EXPECT_GT(raw.first, 3.0 * comp.first) << k;
  }

  // bag_runner on the same bag with ~fixed_frame: the nodelet's compensated depth, to the PNG's
  // resolution (1/256 m).
  {
    const std::filesystem::path out = dir / "bag_runner";
    std::filesystem::remove_all(out);
    std::ofstream((dir / "node.yaml").string()) << "fixed_frame: odom\nmax_time_offset: 0.15\n";
    const auto [status, output] = lsf::test::runCommand(
        std::string(LSF_BAG_RUNNER) + " --bag " + bag_path + " --out " + out.string() +
        " --node-params " + (dir / "node.yaml").string() + " 2>&1");
    EXPECT_EQ(status, 0) << output;
    std::lock_guard<std::mutex> lock(mutex_);
    for (const ros::Time& stamp : image_stamps) {
      char name[40];
      std::snprintf(name, sizeof(name), "%u.%09u.png", stamp.sec, stamp.nsec);
      const cv::Mat png = cv::imread((out / name).string(), cv::IMREAD_UNCHANGED);
      ASSERT_EQ(png.type(), CV_16UC1) << name << "\n" << output;
      const cv::Mat1f& nodelet = depths_["/moving_comp"][stamp];
      int compared = 0, differ = 0;
      for (int v = 0; v < png.rows; ++v) {
        for (int u = 0; u < png.cols; ++u) {
          const float offline = png.at<uint16_t>(v, u) / 256.f, live = nodelet(v, u);
          if (offline == 0.f || !std::isfinite(live)) continue;
          ++compared;
          if (std::abs(offline - live) > 1.f / 256.f) ++differ;
        }
      }
      EXPECT_GT(compared, png.rows * png.cols / 2) << name;
      EXPECT_EQ(differ, 0) << name;
    }
  }

  // A frame whose ego-motion is not on TF (2 s after the last one): /moving_comp warns, naming
  // the frames, and processes it uncompensated; /moving_skip (~motion_failure: skip) drops it.
  const auto& f = frames[0];
  const ros::Time image = image_stamps.back() + ros::Duration(2.0);
  const ros::Time sweep = image + ros::Duration(f.cloud_stamp - f.stamp);
  pubs["/stereo/left/camera_info"].publish(
      lsf::test::cameraInfoMsg(f.camera, false, kCameraFrame, image));
  pubs["/stereo/right/camera_info"].publish(
      lsf::test::cameraInfoMsg(f.camera, true, kRightCameraFrame, image));
  pubs["/stereo/left/image_rect_color"].publish(
      lsf::test::imageMsg(f.left, "bgr8", kCameraFrame, image));
  pubs["/stereo/right/image_rect_color"].publish(
      lsf::test::imageMsg(f.right, "bgr8", kRightCameraFrame, image));
  pubs["/velodyne_points"].publish(lsf::test::cloudMsg(f.cloud, kLidarFrame, sweep));
  ASSERT_TRUE(
      lsf::test::waitFor(60.0,
                         [&] {
                           return have("/moving_comp", image) && have("/moving_raw", image) &&
                                  logged("ego-motion compensation", "(~motion_failure: skip)");
                         }))
      << "the frame without ego-motion was not processed by /moving_comp, or /moving_skip did not "
         "say it skipped it";
  std::cerr << "the frame without ego-motion was processed\n";
  EXPECT_TRUE(logged("'odom'", "(~motion_failure: uncompensated)"));
  EXPECT_TRUE(logged("'velodyne'", "(~motion_failure: uncompensated)"));
  std::lock_guard<std::mutex> lock(mutex_);
  const auto& failed = stats_["/moving_comp"][image];
  EXPECT_FALSE(failed.motion_compensated);
  EXPECT_EQ(failed.motion_failures, 1u);
  EXPECT_EQ(depths_["/moving_skip"].count(image), 0u);
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_moving_rig");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  return RUN_ALL_TESTS();
}
