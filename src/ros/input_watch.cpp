#include "lidar_stereo_fusion/ros/input_watch.h"

#include <cstdio>

namespace lidar_stereo_fusion {

namespace {

std::string seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.1f", s);
  return buf;
}

}  // namespace

InputWatch::InputWatch(std::vector<std::string> topics, double timeout, ThrottledLog& log)
    : timeout_(timeout), log_(log) {
  for (auto& name : topics) topics_.push_back(Topic{std::move(name), false, false, {}});
}

void InputWatch::start(Clock::time_point now) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (Topic& t : topics_) t = Topic{t.name, false, false, now};
  watching_ = true;
}

void InputWatch::stop() {
  std::lock_guard<std::mutex> lock(mutex_);
  watching_ = false;
}

void InputWatch::heard(std::size_t index, Clock::time_point now) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (index >= topics_.size()) return;
  Topic& t = topics_[index];
  t.ever = true;
  t.reported = false;
  t.last = now;
}

std::vector<std::size_t> InputWatch::check(const std::function<uint32_t(std::size_t)>& publishers,
                                           Clock::time_point now) {
  std::vector<std::size_t> silent;
  std::lock_guard<std::mutex> lock(mutex_);
  if (!watching_ || timeout_ <= 0.0) return silent;
  for (std::size_t i = 0; i < topics_.size(); ++i) {
    Topic& t = topics_[i];
    const double quiet = std::chrono::duration<double>(now - t.last).count();
    if (quiet < timeout_) continue;
    silent.push_back(i);
    const uint32_t n = publishers ? publishers(i) : 0;
    const std::string who =
        n == 0 ? "no publisher (driver not running, or the topic not remapped to it?)"
               : std::to_string(n) + " publisher(s)";
    if (!t.ever) {
      log_.warn(t.name, "silent",
                t.name + ": nothing received in the " + seconds(quiet) +
                    " s since the outputs were subscribed; " + who);
    } else if (!t.reported) {
      t.reported = true;
      log_.log(ThrottledLog::Level::kWarn, t.name, "quiet",
               t.name + ": nothing received for " + seconds(quiet) + " s; " + who);
    }
  }
  return silent;
}

}  // namespace lidar_stereo_fusion
