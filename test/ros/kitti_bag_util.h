// Helpers shared by the KITTI bag rostests (test_kitti_bag, test_kitti_bag_rates): running the
// tools, a scratch folder in the build tree and a KITTI drive holding only some frames.
#pragma once

#include <string>
#include <utility>
#include <vector>

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

}  // namespace test
}  // namespace lidar_stereo_fusion
