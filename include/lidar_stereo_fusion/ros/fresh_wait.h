// ~fresh_wait: when the worker gets free, the newest matched set may already be most of an input
// period old, and that age adds to the latency of its outputs (image stamp -> publish). If the next
// set is due within ~fresh_wait, the worker waits for it instead and the older set is dropped
// (counted as any set a newer one replaces): the latency falls by up to ~fresh_wait, the output
// rate a little, since the worker idles for that wait. A set that became ready while the worker
// was idle is fresh and never held.
//
// The input period is the median interval between the last sets that became ready (ROS time, so
// the same under `rosbag play --clock` at any rate). At most half of it is waited for: waiting
// longer than that would hold sets that are fresher than the average. If the next set does not
// come by its due time plus half the wait (a dropped sweep, the sensor stopped), the held set is
// processed after all; InputGate also ends the wait after twice its length in wall time (a paused
// bag). Header-only, no I/O, unit-tested.
#pragma once

#include <algorithm>
#include <cstddef>
#include <deque>
#include <vector>

#include <ros/time.h>
#include <boost/optional.hpp>

namespace lidar_stereo_fusion {

class FreshWait {
 public:
  static constexpr std::size_t kIntervals = 9;  ///< recent intervals the period is the median of
  static constexpr std::size_t kMinIntervals = 3;

  /// `max_wait` [s]: ~fresh_wait; 0 = never wait (always the newest set at once).
  explicit FreshWait(double max_wait = 0.0) : max_wait_(max_wait) {}

  /// A matched set became ready at `t`. A time before the last one (a bag loop) restarts the
  /// history; the same time (two sets at once) adds no interval.
  void ready(const ros::Time& t) {
    if (!last_.isZero() && t < last_) {
      intervals_.clear();
    } else if (!last_.isZero() && t > last_) {
      intervals_.push_back((t - last_).toSec());
      if (intervals_.size() > kIntervals) intervals_.pop_front();
    }
    last_ = t;
  }
  void clear() {
    intervals_.clear();
    last_ = ros::Time();
  }

  /// [s] median interval of the recent sets; 0 while fewer than kMinIntervals are known.
  double period() const {
    if (intervals_.size() < kMinIntervals) return 0.0;
    std::vector<double> sorted(intervals_.begin(), intervals_.end());
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    return sorted[sorted.size() / 2];
  }

  /// The worker is free at `now` with the newest set, the last one ready(): the ROS time until
  /// which to wait for the next one, or none to take this one now.
  boost::optional<ros::Time> holdUntil(const ros::Time& now) const {
    const double period = this->period();
    const double wait = std::min(max_wait_, 0.5 * period);
    if (wait <= 0.0) return boost::none;
    const ros::Time due = last_ + ros::Duration(period);
    if (due <= now || (due - now).toSec() > wait) return boost::none;
    return due + ros::Duration(0.5 * wait);
  }

 private:
  double max_wait_;
  std::deque<double> intervals_;
  ros::Time last_;
};

}  // namespace lidar_stereo_fusion
