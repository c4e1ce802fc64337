// Running a command from a test: the ROS tool tests start the tools as a user would.
#pragma once

#include <string>
#include <utility>

namespace lidar_stereo_fusion {
namespace test {

/// Exit status and output (stdout + stderr) of a shell command; -1 when it could not run or did
/// not exit normally.
std::pair<int, std::string> runCommand(const std::string& command);

}  // namespace test
}  // namespace lidar_stereo_fusion
