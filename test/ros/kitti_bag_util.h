// Helpers shared by the KITTI bag tests (test_kitti_bag, test_kitti_bag_rates,
// test_kitti_to_bag_stream): running the tools, a scratch folder in the build tree, a KITTI drive
// holding only some frames, reading a bag and a KITTI stamp.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include <rosbag/bag.h>
#include <rosbag/message_instance.h>

#include "run_command.h"  // runCommand

namespace lidar_stereo_fusion {
namespace test {

/// KITTI raw date and drive of the sample data (../shared/data).
constexpr const char* kKittiDate = "kitti_raw/2011_09_26";
constexpr const char* kKittiDrive = "2011_09_26_drive_0009_sync";

/// <build folder>/<name>, created.
std::string scratchDir(const std::string& name);

/// A KITTI raw date folder under `scratch` whose drive holds only `frames`: symbolic links to the
/// shared data (nothing is copied). Returns the drive folder.
std::string makeSubsetDrive(const std::string& scratch, const std::vector<std::string>& frames);

/// Every message of the bag at `path` (opened into `bag`, which must outlive the result), grouped
/// by topic, in time order.
std::map<std::string, std::vector<rosbag::MessageInstance>> readBag(const std::string& path,
                                                                    rosbag::Bag& bag);

/// Stamp [s] of `frame` (e.g. "0000000005") in a KITTI timestamps file (line = frame number);
/// -1 if the file has no such line.
double kittiStamp(const std::string& file, const std::string& frame);

}  // namespace test
}  // namespace lidar_stereo_fusion
