// Child processes for the rostests that start programs as a user would (Xvfb, RViz, roslaunch),
// and questions to the master about who subscribes.
#pragma once

#include <sys/types.h>

#include <functional>
#include <string>
#include <vector>

namespace lidar_stereo_fusion {
namespace test {

/// Calls `condition` every 50 ms until it holds or `timeout` [s] of wall time passed.
bool waitFor(double timeout, const std::function<bool()>& condition);

/// A child process (in its own process group) with its output in a log file. stop() and the
/// destructor end the group: `signal` first (SIGTERM unless given), SIGKILL after a grace period.
class Child {
 public:
  Child(const std::vector<std::string>& argv, const std::string& display, const std::string& log);
  ~Child() { stop(); }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  bool running();
  int exitStatus() const { return exit_status_; }
  void stop(int signal = 15 /* SIGTERM */, double grace = 5.0);

 private:
  pid_t pid_ = -1;
  int exit_status_ = -1;
};

/// Runs a command to completion (at most 30 s); returns its exit status.
int run(const std::vector<std::string>& argv, const std::string& display);

/// True when `program` is an executable in a PATH folder.
bool onPath(const std::string& program);

/// A display number no X server uses (-1: none).
int freeDisplay();

/// True when node `node` (any node when empty) subscribes to `topic` (asks the master).
bool hasSubscriber(const std::string& topic, const std::string& node = "");

/// True when the master knows node `name`.
bool nodeRegistered(const std::string& name);

}  // namespace test
}  // namespace lidar_stereo_fusion
