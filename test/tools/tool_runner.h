// Runs the package's tools from the tests: where the executable is (next to the test binary in
// the plain CMake build, in the catkin devel space otherwise) and what a run printed and returned.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace lidar_stereo_fusion {
namespace test {

/// The tool's executable, or "" when it is not built.
inline std::string toolPath(const std::string& tool) {
  namespace fs = std::filesystem;
  const fs::path build(LSF_BINARY_DIR);
  for (const fs::path& candidate :
       {build / tool, build / ".." / ".." / "devel" / "lib" / "lidar_stereo_fusion" / tool}) {
    if (fs::is_regular_file(candidate)) return candidate.string();
  }
  return "";
}

struct RunResult {
  int status = -1;  ///< the exit code; -1 when the process did not exit (a signal)
  std::string out, err;
};

inline std::string readAll(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Runs `command` (a shell command line) with stdout and stderr captured through files in
/// `scratch`.
inline RunResult runCommand(const std::string& command, const std::filesystem::path& scratch) {
  const std::filesystem::path out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  const int raw = std::system((command + " > " + out.string() + " 2> " + err.string()).c_str());
  RunResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = readAll(out);
  r.err = readAll(err);
  return r;
}

}  // namespace test
}  // namespace lidar_stereo_fusion
