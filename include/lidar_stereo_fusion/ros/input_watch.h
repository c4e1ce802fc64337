// Names the input topics that publish nothing: a rig whose driver is missing, not running or not
// remapped otherwise waits in silence. While the inputs are subscribed, a topic that has sent
// nothing for `timeout` seconds is warned about (the caller's clock: wall time on a rig, ROS time
// under /use_sim_time, where a slowed or ended bag is not silence), naming the topic and how many
// publishers it has: repeatedly (throttled) while it has never sent anything, once when it went
// quiet after sending (e.g. the end of a bag), again only after it sent something.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "lidar_stereo_fusion/ros/node_support.h"

namespace lidar_stereo_fusion {

class InputWatch {
 public:
  using Clock = std::chrono::steady_clock;

  /// `topics`: resolved names, in the order of the indices given to heard(). timeout [s] <= 0: off.
  InputWatch(std::vector<std::string> topics, double timeout, ThrottledLog& log);

  /// Starts watching (the inputs were just subscribed) / stops (unsubscribed).
  void start(Clock::time_point now = Clock::now());
  void stop();
  /// A message arrived on topic `index` (any thread).
  void heard(std::size_t index, Clock::time_point now = Clock::now());
  /// Warns about the silent topics; `publishers(index)` is the topic's publisher count. Returns
  /// the indices of the topics found silent (for tests).
  std::vector<std::size_t> check(const std::function<uint32_t(std::size_t)>& publishers,
                                 Clock::time_point now = Clock::now());

 private:
  struct Topic {
    std::string name;
    bool ever = false;       ///< sent something since start()
    bool reported = false;   ///< went quiet after sending, and that was said
    Clock::time_point last;  ///< last message, or start()
  };

  double timeout_;
  ThrottledLog& log_;
  std::mutex mutex_;  ///< the one lock: topics_, watching_
  std::vector<Topic> topics_;
  bool watching_ = false;
};

}  // namespace lidar_stereo_fusion
