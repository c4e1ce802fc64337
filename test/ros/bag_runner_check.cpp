#include "bag_runner_check.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "depth_agreement.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "run_command.h"

namespace fs = std::filesystem;

namespace lidar_stereo_fusion {
namespace test {

/// bag_runner on the replayed bag: a depth PNG per frame, named by the left stamp, equal to the
/// nodelet's published depth as the PNG rounds it, and within the replay test's tolerances of
/// kitti_runner's PNG; frames.csv names every set ok.
void expectBagRunnerAgrees(const std::string& bag_path, const std::string& out,
                           const std::vector<ros::Time>& stamps,
                           const std::vector<std::string>& frames,
                           const std::vector<cv::Mat1f>& nodelet_depths,
                           const std::string& runner_out, double fB) {
  fs::remove_all(out);
  const auto [status, output] =
      runCommand(std::string(LSF_BAG_RUNNER) + " --bag " + bag_path + " --out " + out +
                 " --params " + LSF_SOURCE_DIR + "/config/fusion.yaml");
  ASSERT_EQ(status, 0) << output;
  std::ifstream csv(out + "/frames.csv");
  std::string line;
  std::getline(csv, line);
  size_t rows = 0;
  for (; std::getline(csv, line); ++rows) EXPECT_NE(line.find(",ok,"), std::string::npos) << line;
  EXPECT_EQ(rows, stamps.size());
  ASSERT_EQ(nodelet_depths.size(), stamps.size());
  for (size_t i = 0; i < stamps.size(); ++i) {
    char name[40];
    std::snprintf(name, sizeof(name), "%u.%09u.png", stamps[i].sec, stamps[i].nsec);
    SCOPED_TRACE(std::string("bag_runner ") + name);
    const cv::Mat png = cv::imread(out + "/" + name, cv::IMREAD_UNCHANGED);
    ASSERT_EQ(png.type(), CV_16UC1);
    const cv::Mat expected = kittiDepthValues(nodelet_depths[i]);
    ASSERT_EQ(png.size(), expected.size());
    EXPECT_EQ(cv::countNonZero(png != expected), 0) << "pixels where bag_runner's PNG differs "
                                                       "from the nodelet's depth";
    const auto a =
        agreeWithRunner(kitti::readDepthPng(out + "/" + name),
                        kitti::readDepthPng(runner_out + "/" + frames.at(i) + ".png"), fB);
    EXPECT_GT(a.both, a.pixels / 2);
    EXPECT_LE(a.validity_differs, a.pixels / 1000);
    EXPECT_LE(a.bad_1px, a.both / 1000);
    EXPECT_LT(a.mean_abs, 0.01);
  }
}

}  // namespace test
}  // namespace lidar_stereo_fusion
