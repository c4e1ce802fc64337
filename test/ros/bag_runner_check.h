// The check of bag_runner in the KITTI bag rostest (test_kitti_bag): its depth PNGs against the
// nodelet's published depth of the same sets and against kitti_runner's PNGs.
#pragma once

#include <string>
#include <vector>

#include <ros/time.h>
#include <opencv2/core.hpp>

namespace lidar_stereo_fusion {
namespace test {

/// Runs bag_runner (LSF_BAG_RUNNER) on `bag_path` into `out` with config/fusion.yaml and expects
/// a depth PNG per stamp (<sec>.<nsec>.png) equal to the nodelet's depth of that set as the PNG
/// rounds it, within the bag rostest's tolerance of kitti_runner's `runner_out`/<frame>.png
/// (`frames`, in the order of `stamps`; `fB` = fx * baseline), and a frames.csv naming every set
/// ok.
void expectBagRunnerAgrees(const std::string& bag_path, const std::string& out,
                           const std::vector<ros::Time>& stamps,
                           const std::vector<std::string>& frames,
                           const std::vector<cv::Mat1f>& nodelet_depths,
                           const std::string& runner_out, double fB);

}  // namespace test
}  // namespace lidar_stereo_fusion
