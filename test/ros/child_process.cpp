#include "child_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <thread>

#include <ros/master.h>
#include <ros/this_node.h>
#include <xmlrpcpp/XmlRpcValue.h>

namespace lidar_stereo_fusion {
namespace test {

bool waitFor(double timeout, const std::function<bool()>& condition) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
  while (std::chrono::steady_clock::now() < end) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return condition();
}

Child::Child(const std::vector<std::string>& argv, const std::string& display,
             const std::string& log) {
  pid_ = fork();
  if (pid_ == 0) {
    setpgid(0, 0);  // its own group: stop() ends whatever it started too (roslaunch's nodes)
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
    }
    if (!display.empty()) setenv("DISPLAY", display.c_str(), 1);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execvp(args[0], args.data());
    _exit(127);
  }
  if (pid_ > 0) setpgid(pid_, pid_);  // also here: no race with the first stop()
}

bool Child::running() {
  if (pid_ <= 0) return false;
  int status = 0;
  if (waitpid(pid_, &status, WNOHANG) == pid_) {
    exit_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    kill(-pid_, SIGKILL);  // anything of its group left behind
    pid_ = -1;
    return false;
  }
  return true;
}

void Child::stop(int signal, double grace) {
  if (!running()) return;
  kill(-pid_, signal);
  if (!waitFor(grace, [&] { return !running(); })) {
    kill(-pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }
}

int run(const std::vector<std::string>& argv, const std::string& display) {
  Child child(argv, display, "/dev/null");
  if (!waitFor(30.0, [&] { return !child.running(); })) return -1;
  return child.exitStatus();
}

bool onPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "";
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::string candidate = dirs.substr(start, end - start) + "/" + program;
    if (access(candidate.c_str(), X_OK) == 0) return true;
    start = end + 1;
  }
  return false;
}

int freeDisplay() {
  for (int n = 90 + static_cast<int>(getpid() % 50); n < 400; ++n) {
    const std::string lock = "/tmp/.X" + std::to_string(n) + "-lock";
    const std::string socket = "/tmp/.X11-unix/X" + std::to_string(n);
    if (access(lock.c_str(), F_OK) != 0 && access(socket.c_str(), F_OK) != 0) return n;
  }
  return -1;
}

bool hasSubscriber(const std::string& topic, const std::string& node) {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  if (!ros::master::execute("getSystemState", request, response, payload, true)) return false;
  const XmlRpc::XmlRpcValue& subscribers = payload[1];
  for (int i = 0; i < subscribers.size(); ++i) {
    if (static_cast<std::string>(subscribers[i][0]) != topic) continue;
    if (node.empty()) return true;
    const XmlRpc::XmlRpcValue& nodes = subscribers[i][1];
    for (int k = 0; k < nodes.size(); ++k) {
      if (static_cast<std::string>(nodes[k]) == node) return true;
    }
  }
  return false;
}

bool nodeRegistered(const std::string& name) {
  std::vector<std::string> nodes;
  if (!ros::master::getNodes(nodes)) return false;
  return std::find(nodes.begin(), nodes.end(), name) != nodes.end();
}

}  // namespace test
}  // namespace lidar_stereo_fusion
