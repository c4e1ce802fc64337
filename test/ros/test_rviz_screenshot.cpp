// rostest: RViz with rviz/fusion.rviz, on a virtual X server (Xvfb), draws the fused cloud.
//
// The test publishes one frame of the simulated street again and again (so that the picture is
// still) in two phases and takes a screenshot of each with ImageMagick's `import`, once the
// picture has settled (two screenshots in a row agree):
//   A  images and LiDAR sweeps stamped half a period apart: no sweep matches (max_time_offset), so
//      the fusion publishes nothing, while RViz draws the raw LiDAR points;
//   B  sweeps stamped like the images: the fusion publishes points2, which RViz adds.
// The 3D view is found in A as the bounding box of RViz's background colour; the share of its
// pixels that change from A to B must be large, and from A to a second screenshot of phase A
// small. Screenshots are written to LSF_BINARY_DIR (rviz_phase_a.png, rviz_fusion.png).
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <ros/master.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <xmlrpcpp/XmlRpcValue.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "child_process.h"
#include "synthetic_input.h"

namespace lsf = lidar_stereo_fusion;

namespace {

constexpr int kScreenWidth = 1600, kScreenHeight = 1000;
constexpr const char* kFusionProcess = "/fusion/fusion_manager";  ///< fusion.launch's manager
const cv::Vec3b kBackground(48, 48, 48);  ///< Global Options / Background Color of fusion.rviz

using lsf::test::Child;
using lsf::test::freeDisplay;
using lsf::test::hasSubscriber;
using lsf::test::onPath;
using lsf::test::run;
using lsf::test::waitFor;

/// Publishes frame 0 of the street at 2 Hz (a wall timer on the spinner's threads); the sweep
/// stamp offset can change. Counts the sets it published, so that a test waits for sets, not time.
class Publisher {
 public:
  explicit Publisher(const lsf::sim::SyntheticFrame& frame) : frame_(frame) {
    left_image_ = nh_.advertise<sensor_msgs::Image>("/stereo/left/image_rect_color", 2);
    left_info_ = nh_.advertise<sensor_msgs::CameraInfo>("/stereo/left/camera_info", 2);
    right_image_ = nh_.advertise<sensor_msgs::Image>("/stereo/right/image_rect_color", 2);
    right_info_ = nh_.advertise<sensor_msgs::CameraInfo>("/stereo/right/camera_info", 2);
    cloud_ = nh_.advertise<sensor_msgs::PointCloud2>("/velodyne_points", 2);
    auto tf = lsf::test::lidarToCameraTf(frame.T_cam_lidar, lsf::test::kCameraFrame,
                                         lsf::test::kLidarFrame);
    tf.header.stamp = ros::Time::now();
    tf_.sendTransform(tf);
    timer_ = nh_.createWallTimer(ros::WallDuration(0.5),
                                 [this](const ros::WallTimerEvent&) { publishSet(); });
  }
  ~Publisher() { timer_.stop(); }
  void setSweepOffset(double seconds) { sweep_offset_ = seconds; }
  /// Waits until `n` more sets have been published; false after `timeout` [s].
  bool waitForSets(int n, double timeout = 10.0) {
    const int target = published_ + n;
    return waitFor(timeout, [&] { return published_ >= target; });
  }

 private:
  void publishSet() {
    using lsf::test::kCameraFrame;
    using lsf::test::kRightCameraFrame;
    const ros::Time stamp = ros::Time::now();
    left_info_.publish(lsf::test::cameraInfoMsg(frame_.camera, false, kCameraFrame, stamp));
    right_info_.publish(lsf::test::cameraInfoMsg(frame_.camera, true, kRightCameraFrame, stamp));
    left_image_.publish(lsf::test::imageMsg(frame_.left, "bgr8", kCameraFrame, stamp));
    right_image_.publish(lsf::test::imageMsg(frame_.right, "bgr8", kRightCameraFrame, stamp));
    cloud_.publish(lsf::test::cloudMsg(frame_.cloud, lsf::test::kLidarFrame,
                                       stamp + ros::Duration(sweep_offset_.load())));
    ++published_;
  }

  const lsf::sim::SyntheticFrame& frame_;
  ros::NodeHandle nh_;
  ros::Publisher left_image_, left_info_, right_image_, right_info_, cloud_;
  tf2_ros::StaticTransformBroadcaster tf_;
  std::atomic<double> sweep_offset_{0.25};
  std::atomic<int> published_{0};
  ros::WallTimer timer_;
};

/// RViz's 3D view: the longest run of columns, then of rows within them, in which at least a
/// quarter of the pixels have the background colour `colour`. (A bounding box of all such pixels
/// would also take in dark pixels of the image panels.)
cv::Rect renderView(const cv::Mat3b& image, const cv::Vec3b& colour) {
  cv::Mat1b is_background(image.size(), uint8_t{0});
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const cv::Vec3b& p = image(y, x);
      is_background(y, x) =
          std::abs(p[0] - colour[0]) + std::abs(p[1] - colour[1]) + std::abs(p[2] - colour[2]) <= 3;
    }
  }
  // Longest run of indices i in [0, n) where count(j) >= a quarter of `length` for some j within
  // 3 of i (so that one-pixel grid lines across the view do not split it).
  const auto longestRun = [](int n, int length, const std::function<int(int)>& count) {
    std::vector<bool> dense_at(n);
    for (int i = 0; i < n; ++i) dense_at[i] = 4 * count(i) >= length;
    int best_start = 0, best_length = 0, start = -1;
    for (int i = 0; i <= n; ++i) {
      bool dense = false;
      for (int j = std::max(0, i - 3); i < n && j <= std::min(n - 1, i + 3); ++j) {
        dense = dense || dense_at[j];
      }
      if (dense && start < 0) start = i;
      if (!dense && start >= 0) {
        if (i - start > best_length) {
          best_start = start;
          best_length = i - start;
        }
        start = -1;
      }
    }
    return std::make_pair(best_start, best_length);
  };
  const auto cols = longestRun(image.cols, image.rows,
                               [&](int x) { return cv::countNonZero(is_background.col(x)); });
  if (cols.second == 0) return cv::Rect();
  const cv::Mat1b band = is_background.colRange(cols.first, cols.first + cols.second);
  const auto rows =
      longestRun(image.rows, cols.second, [&](int y) { return cv::countNonZero(band.row(y)); });
  return cv::Rect(cols.first, rows.first, cols.second, rows.second);
}

/// Fraction of the pixels in `box` whose colour differs by more than 60 (L1 over BGR).
double changedFraction(const cv::Mat3b& a, const cv::Mat3b& b, const cv::Rect& box) {
  int changed = 0;
  for (int y = box.y; y < box.y + box.height; ++y) {
    for (int x = box.x; x < box.x + box.width; ++x) {
      const cv::Vec3b& p = a(y, x);
      const cv::Vec3b& q = b(y, x);
      changed += std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]) > 60;
    }
  }
  return box.area() > 0 ? static_cast<double>(changed) / box.area() : 0.0;
}

/// Screenshots of `display` into `path`, one after each new input set, until two in a row differ
/// in under 1 % of the screen's pixels: RViz has drawn what it received. False after `timeout` [s].
bool settledShot(const std::string& display, const std::string& path, Publisher& publisher,
                 double timeout = 60.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
  cv::Mat3b previous;
  while (std::chrono::steady_clock::now() < end) {
    if (!publisher.waitForSets(1) || run({"import", "-window", "root", path}, display) != 0) {
      return false;
    }
    const cv::Mat3b shot = cv::imread(path, cv::IMREAD_COLOR);
    if (!shot.empty() && shot.size() == previous.size() &&
        changedFraction(previous, shot, cv::Rect(0, 0, shot.cols, shot.rows)) < 0.01) {
      return true;
    }
    previous = shot;
  }
  return false;
}

/// Fraction of the pixels in `box` of a strong colour (HSV saturation > 150 and value > 80 of
/// 255): the colour maps of depth and disparity, not grey panels or the background.
double colourfulFraction(const cv::Mat3b& image, const cv::Rect& box) {
  const cv::Rect inside = box & cv::Rect(0, 0, image.cols, image.rows);
  if (inside.area() == 0) return 0.0;
  cv::Mat hsv;
  cv::cvtColor(image(inside), hsv, cv::COLOR_BGR2HSV);
  int strong = 0;
  for (int y = 0; y < hsv.rows; ++y) {
    for (int x = 0; x < hsv.cols; ++x) {
      const cv::Vec3b& p = hsv.at<cv::Vec3b>(y, x);
      strong += p[1] > 150 && p[2] > 80;
    }
  }
  return static_cast<double>(strong) / inside.area();
}

}  // namespace

TEST(RvizScreenshot, FusedCloudIsDrawn) {
  for (const char* program : {"Xvfb", "rviz", "import"}) {
    ASSERT_TRUE(onPath(program)) << program << " is not installed (scripts/install_deps.sh)";
  }
  const std::string out_dir = LSF_BINARY_DIR;
  const std::string config = std::string(LSF_SOURCE_DIR) + "/rviz/fusion.rviz";

  const int display_number = freeDisplay();
  ASSERT_GE(display_number, 0);
  const std::string display = ":" + std::to_string(display_number);
  Child xvfb({"Xvfb", display, "-screen", "0",
              std::to_string(kScreenWidth) + "x" + std::to_string(kScreenHeight) + "x24",
              "-nolisten", "tcp"},
             "", out_dir + "/rviz_test_xvfb.log");
  const std::string socket = "/tmp/.X11-unix/X" + std::to_string(display_number);
  ASSERT_TRUE(waitFor(15.0, [&] { return access(socket.c_str(), F_OK) == 0; }))
      << "Xvfb did not start on " << display;

  const auto frames = lsf::test::makeFrames(1, 621, 188, 64, 0.18);
  Publisher publisher(frames[0]);

  ros::NodeHandle nh;
  std::atomic<int> fused{0};
  auto points_sub = nh.subscribe<sensor_msgs::PointCloud2>(
      "/fusion/points2", 2, [&](const sensor_msgs::PointCloud2ConstPtr&) { ++fused; });

  Child rviz({"rviz", "-d", config}, display, out_dir + "/rviz_test_rviz.log");
  ASSERT_TRUE(waitFor(90.0,
                      [&] {
                        return hasSubscriber("/velodyne_points") &&
                               hasSubscriber("/stereo/left/image_rect_color");
                      }))
      << "RViz did not subscribe (see " << out_dir << "/rviz_test_rviz.log)";
  ASSERT_TRUE(rviz.running());

  // Phase A: raw LiDAR only; the fusion finds no sweep within max_time_offset. It has its inputs
  // (RViz subscribes to its outputs) and four sets to match; RViz's picture settles.
  ASSERT_TRUE(waitFor(30.0, [&] { return hasSubscriber("/velodyne_points", kFusionProcess); }))
      << "the fusion did not subscribe to its inputs";
  ASSERT_TRUE(publisher.waitForSets(4));
  const std::string shot_a = out_dir + "/rviz_phase_a.png",
                    shot_a2 = out_dir + "/rviz_phase_a2.png";
  ASSERT_TRUE(settledShot(display, shot_a, publisher)) << "RViz's picture does not settle";
  const int fused_in_a = fused;
  ASSERT_TRUE(publisher.waitForSets(3));  // the picture stays as it is: a second shot later
  ASSERT_EQ(run({"import", "-window", "root", shot_a2}, display), 0);
  EXPECT_EQ(fused_in_a, 0) << "the fusion published although no sweep matched";

  // Phase B: sweeps match; the fused cloud appears, and RViz's picture settles again.
  publisher.setSweepOffset(0.0);
  ASSERT_TRUE(waitFor(60.0, [&] { return fused >= 2; })) << "no fused cloud published";
  const std::string shot_b = out_dir + "/rviz_fusion.png";
  ASSERT_TRUE(settledShot(display, shot_b, publisher)) << "RViz's picture does not settle";
  EXPECT_TRUE(rviz.running()) << "RViz died";

  const cv::Mat3b a = cv::imread(shot_a, cv::IMREAD_COLOR);
  const cv::Mat3b a2 = cv::imread(shot_a2, cv::IMREAD_COLOR);
  const cv::Mat3b b = cv::imread(shot_b, cv::IMREAD_COLOR);
  ASSERT_FALSE(a.empty());
  ASSERT_FALSE(b.empty());
  ASSERT_EQ(a.size(), b.size());
  const cv::Rect view = renderView(a, kBackground);
  ASSERT_GT(view.area(), a.total() / 8) << "RViz's 3D view was not found in " << shot_a;
  const double still = changedFraction(a, a2, view);
  const double fused_change = changedFraction(a, b, view);
  std::cout << "3D view " << view << ": changed " << 100.0 * still << " % within phase A, "
            << 100.0 * fused_change << " % once the fused cloud is drawn\n";
  EXPECT_LT(still, 0.01) << "the view changes by itself; the comparison would mean nothing";
  EXPECT_GT(fused_change, 0.05) << "the fused cloud is not drawn (compare " << shot_a << " and "
                                << shot_b << ")";
  // Issue 25, point 9: the panels where rviz/fusion.rviz puts them, readable. Right of the 3D
  // view, top to bottom: the left image, the depth and the disparity, the last two in colour
  // (TURBO, a scale bar below); the left dock below the display list holds no picture (the depth
  // panel was dropped there, small, when its saved name did not match the display's).
  const cv::Rect right_dock(view.br().x + 20, view.y, b.cols - view.br().x - 20, view.height);
  const cv::Rect left_below(0, view.y + 3 * view.height / 4, std::max(1, view.x - 20),
                            view.height / 4);
  const int third = right_dock.height / 3;
  const cv::Rect depth_panel(right_dock.x, right_dock.y + third, right_dock.width, third);
  const cv::Rect disparity_panel(right_dock.x, right_dock.y + 2 * third, right_dock.width, third);
  const double depth_colour = colourfulFraction(b, depth_panel);
  const double disparity_colour = colourfulFraction(b, disparity_panel);
  const double left_dock_colour = colourfulFraction(b, left_below);
  std::cout << "colourful: depth panel " << 100 * depth_colour << " %, disparity panel "
            << 100 * disparity_colour << " %, left dock below the displays "
            << 100 * left_dock_colour << " %\n";
  EXPECT_GT(depth_colour, 0.10) << "no coloured depth in the middle of the right dock (" << shot_b
                                << ")";
  EXPECT_GT(disparity_colour, 0.10)
      << "no coloured disparity at the bottom of the right dock (" << shot_b << ")";
  EXPECT_LT(left_dock_colour, 0.01) << "a picture in the left dock (" << shot_b << ")";
  rviz.stop();
  xvfb.stop();
}

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_rviz_screenshot");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  ros::shutdown();
  return result;
}
