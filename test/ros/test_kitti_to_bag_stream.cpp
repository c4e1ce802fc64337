// kitti_to_bag --period / --cycles: the sample's frames (0.5 s apart) restamped as a stream at the
// sensor's rate and repeated, for rate tests at real time. Exact stamps: frame k's images at the
// first image stamp + k * period, each sweep at its own frame's offset from its images; the
// repeated frames carry the same data. And the command-line mistakes these options allow.
// No ROS master needed. Missing data fails under CI=true and skips otherwise.
#include <filesystem>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>

#include "data/data_guard.h"
#include "kitti_bag_util.h"

namespace fs = std::filesystem;
namespace lt = lidar_stereo_fusion::test;

namespace {

std::string scratchDir() { return lt::scratchDir("test_kitti_to_bag_stream"); }

}  // namespace

TEST(KittiToBagStream, RestampsTheFramesAtThePeriodAndRepeatsThem) {
  LSF_REQUIRE_DATA(std::string(lt::kKittiDate) + "/" + lt::kKittiDrive);
  const std::vector<std::string> names = {"0000000005", "0000000010"};
  const std::string drive = lt::makeSubsetDrive(scratchDir(), names);
  const std::string bag_path = scratchDir() + "/stream.bag";
  fs::remove(bag_path);
  const auto [status, output] =
      lt::runCommand(std::string(LSF_KITTI_TO_BAG) + " --kitti-raw " + drive + " --out " +
                     bag_path + " --period 0.1 --cycles 3");
  ASSERT_EQ(status, 0) << output;
  EXPECT_NE(output.find("wrote 6 frame(s)"), std::string::npos) << output;
  // KITTI's sweeps end ~40 ms after their images: less than half the period, no warning.
  EXPECT_EQ(output.find("neighbouring frame"), std::string::npos) << output;

  rosbag::Bag bag;
  auto topics = lt::readBag(bag_path, bag);
  ASSERT_EQ(topics["/tf_static"].size(), 1u);
  const auto& lefts = topics["/stereo/left/image_rect_color"];
  const auto& rights = topics["/stereo/right/image_rect_color"];
  const auto& infos = topics["/stereo/left/camera_info"];
  const auto& clouds = topics["/velodyne_points"];
  ASSERT_EQ(lefts.size(), 6u);
  ASSERT_EQ(rights.size(), 6u);
  ASSERT_EQ(infos.size(), 6u);
  ASSERT_EQ(clouds.size(), 6u);

  const std::string stamps = drive + "/image_02/timestamps.txt";
  const std::string sweep_ends = drive + "/velodyne_points/timestamps_end.txt";
  const double first = lt::kittiStamp(stamps, names[0]);
  std::vector<sensor_msgs::ImageConstPtr> images;
  std::vector<sensor_msgs::PointCloud2ConstPtr> sweeps;
  for (size_t k = 0; k < lefts.size(); ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const auto left = lefts[k].instantiate<sensor_msgs::Image>();
    const auto right = rights[k].instantiate<sensor_msgs::Image>();
    const auto info = infos[k].instantiate<sensor_msgs::CameraInfo>();
    const auto cloud = clouds[k].instantiate<sensor_msgs::PointCloud2>();
    ASSERT_TRUE(left && right && info && cloud);
    const std::string& name = names[k % names.size()];
    EXPECT_NEAR(left->header.stamp.toSec(), first + 0.1 * static_cast<double>(k), 1e-6);
    EXPECT_EQ(right->header.stamp, left->header.stamp);
    EXPECT_EQ(info->header.stamp, left->header.stamp);
    EXPECT_EQ(lefts[k].getTime(), left->header.stamp);
    EXPECT_EQ(left->header.seq, k);
    const double offset = lt::kittiStamp(sweep_ends, name) - lt::kittiStamp(stamps, name);
    EXPECT_NEAR((cloud->header.stamp - left->header.stamp).toSec(), offset, 1e-6);
    EXPECT_EQ(clouds[k].getTime(), cloud->header.stamp);
    EXPECT_TRUE(cloud->is_dense);
    images.push_back(left);
    sweeps.push_back(cloud);
  }
  // The cycles repeat the frames' data; the two frames differ.
  for (size_t k = names.size(); k < images.size(); ++k) {
    EXPECT_EQ(images[k]->data, images[k - names.size()]->data) << k;
    EXPECT_EQ(sweeps[k]->data, sweeps[k - names.size()]->data) << k;
  }
  EXPECT_NE(images[0]->data, images[1]->data);
  bag.close();
  fs::remove(bag_path);
}

TEST(KittiToBagStream, BadPeriodOrCyclesAreUsageErrors) {
  const std::string bag_path = scratchDir() + "/bad.bag";
  fs::remove(bag_path);
  const std::string command =
      std::string(LSF_KITTI_TO_BAG) + " --kitti-raw x --out " + bag_path + " ";
  for (const auto& [args, named] : std::vector<std::pair<std::string, std::string>>{
           {"--cycles 2", "--cycles needs --period"},
           {"--period 0", "--period must be a number in"},
           {"--period -0.1", "--period must be a number in"},
           {"--period 0.1s", "--period must be a number in"},
           {"--period 11", "--period must be a number in"},
           {"--period nan", "--period must be a number in"},
           {"--period 0.1 --cycles 0", "--cycles must be an integer in"},
           {"--period 0.1 --period 0.2", "--period given twice"}}) {
    SCOPED_TRACE(args);
    const auto [status, output] = lt::runCommand(command + args);
    EXPECT_EQ(status, 2) << output;
    EXPECT_NE(output.find(named), std::string::npos) << output;
  }
  EXPECT_FALSE(fs::exists(bag_path));
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
