// The names shared by the two files of the KITTI bag rostest (test_kitti_bag.cpp: the bag
// kitti_to_bag writes; test_kitti_bag_replay.cpp: the bag through the nodelet): the sample drive,
// the left optical frame, the tools' helpers and the test's scratch folder.
#pragma once

#include <string>

#include "kitti_bag_util.h"

namespace kitti_bag_test {

constexpr const char* kDate = lidar_stereo_fusion::test::kKittiDate;    ///< under the data folder
constexpr const char* kDrive = lidar_stereo_fusion::test::kKittiDrive;  ///< in kDate
constexpr const char* kLeftFrame = "left_camera_optical_frame";

using lidar_stereo_fusion::test::kittiStamp;
using lidar_stereo_fusion::test::readBag;
using lidar_stereo_fusion::test::runCommand;

/// <build folder>/test_kitti_bag, created.
inline std::string scratchDir() { return lidar_stereo_fusion::test::scratchDir("test_kitti_bag"); }

}  // namespace kitti_bag_test
