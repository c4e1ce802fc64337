// Matching LiDAR sweeps to synchronised image sets by stamp. Header-only, no I/O, unit-tested.
//
// velodyne_pointcloud stamps a sweep at its last packet, so the sweep that covers an image is
// usually stamped after it and arrives after it. An image set therefore waits (pending) until a
// sweep stamped at or after the image has arrived -- from then on no later sweep can be nearer --
// or until ROS time has moved `max_wait` past its arrival, and then takes the sweep nearest in
// time, looking both ways, if that is within `max_time_offset`; otherwise it is given up
// ("unmatched").
//
// Every "now" is ROS time (ros::Time::now(): simulated time under `rosbag play --clock` with
// /use_sim_time), never wall time: a bag played at -r 0.05 or paused pairs exactly as at real
// time, because the wait scales with the playback.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <deque>
#include <utility>
#include <vector>

#include <ros/time.h>

namespace lidar_stereo_fusion {

template <class Images, class Sweep>
class FrameMatcher {
 public:
  struct Params {
    double max_time_offset = 0.1;        ///< [s] largest |sweep stamp - image stamp| accepted
    double max_wait = 0.3;               ///< [s] ROS time an image set waits for a later sweep
    std::size_t sweep_buffer_size = 10;  ///< recent sweeps kept
    std::size_t max_pending = 4;  ///< image sets waiting at most; the oldest is decided first
    /// [s] a stamp this much older than the last one is a restart of time (a bag played with
    /// --loop, a restarted driver), not disorder: everything buffered is forgotten and the message
    /// accepted. Smaller steps back are out of order and dropped.
    double restart_step = 1.0;
  };

  struct Match {
    Images images;
    Sweep sweep;
    ros::Time image_stamp, sweep_stamp;
  };

  /// What one call decided.
  struct Events {
    std::vector<Match> ready;          ///< matched sets, oldest first
    std::vector<ros::Time> unmatched;  ///< image stamps given up: no sweep within max_time_offset
    /// Per entry of `unmatched`: true when it was decided by waiting (max_wait or max_pending)
    /// with no sweep at or after it yet, false when a later sweep had come and none was near.
    std::vector<bool> unmatched_waited;
    bool out_of_order = false;  ///< the message passed in was not newer than the last one (dropped)
    bool restarted = false;     ///< time restarted (see Params::restart_step): buffers were cleared
    std::size_t discarded = 0;  ///< image sets still waiting that the restart threw away
  };

  explicit FrameMatcher(const Params& params = Params()) : params_(params) {}
  void setParams(const Params& params) { params_ = params; }
  const Params& params() const { return params_; }

  /// Adds a synchronised image set stamped `stamp`, arriving at ROS time `now`.
  Events addImages(const ros::Time& stamp, Images images, const ros::Time& now) {
    Events events;
    if (have_image_ && stamp <= last_image_stamp_) {
      if ((last_image_stamp_ - stamp).toSec() <= params_.restart_step) {
        events.out_of_order = true;
        return events;
      }
      events.restarted = true;
      events.discarded = clear();
    }
    have_image_ = true;
    last_image_stamp_ = stamp;
    pending_.push_back({stamp, std::move(images), now});
    resolve(events, now);
    return events;
  }

  /// Adds a sweep stamped `stamp`, arriving at ROS time `now`.
  Events addSweep(const ros::Time& stamp, Sweep sweep, const ros::Time& now) {
    Events events;
    if (!sweeps_.empty() && stamp <= sweeps_.back().first) {
      if ((sweeps_.back().first - stamp).toSec() <= params_.restart_step) {
        events.out_of_order = true;
        return events;
      }
      events.restarted = true;
      events.discarded = clear();
    }
    sweeps_.emplace_back(stamp, std::move(sweep));
    while (sweeps_.size() > std::max<std::size_t>(params_.sweep_buffer_size, 1))
      sweeps_.pop_front();
    resolve(events, now);
    return events;
  }

  /// Decides sets that have waited long enough (ROS time `now`); call periodically.
  Events poll(const ros::Time& now) {
    Events events;
    resolve(events, now);
    return events;
  }

  /// Forgets everything (e.g. when the ROS clock jumps back). Returns the pending sets dropped.
  std::size_t clear() {
    const std::size_t n = pending_.size();
    pending_.clear();
    sweeps_.clear();
    have_image_ = false;
    return n;
  }

  std::size_t pendingCount() const { return pending_.size(); }
  std::size_t sweepCount() const { return sweeps_.size(); }

 private:
  struct Pending {
    ros::Time stamp;
    Images images;
    ros::Time arrival;  ///< ROS time of arrival; zero until ROS time is known (resolve)
  };

  void resolve(Events& events, const ros::Time& now) {
    // ROS time zero is time not yet known (/use_sim_time before the first /clock): a bag's first
    // image set can come before the clock's first tick, on its own connection. Its wait starts at
    // the first known time, or that tick (a jump from zero) would give it up at once.
    if (!now.isZero()) {
      for (Pending& p : pending_) {
        if (p.arrival.isZero()) p.arrival = now;
      }
    }
    while (!pending_.empty()) {
      Pending& p = pending_.front();
      const bool later_sweep_seen = !sweeps_.empty() && sweeps_.back().first >= p.stamp;
      // ROS time that went back (a bag loop) is not waiting: the caller clears the buffers then.
      const bool waited_enough = now >= p.arrival && (now - p.arrival).toSec() >= params_.max_wait;
      const bool too_many = pending_.size() > std::max<std::size_t>(params_.max_pending, 1);
      if (!later_sweep_seen && !waited_enough && !too_many) break;  // later ones wait too
      const auto best = nearestSweep(p.stamp);
      if (best != nullptr) {
        events.ready.push_back({std::move(p.images), best->second, p.stamp, best->first});
      } else {
        events.unmatched.push_back(p.stamp);
        events.unmatched_waited.push_back(!later_sweep_seen);
      }
      pending_.pop_front();
    }
  }

  const std::pair<ros::Time, Sweep>* nearestSweep(const ros::Time& stamp) const {
    const std::pair<ros::Time, Sweep>* best = nullptr;
    double best_dt = params_.max_time_offset;
    for (const auto& s : sweeps_) {
      const double dt = std::abs((s.first - stamp).toSec());
      if (dt <= best_dt) {
        best_dt = dt;
        best = &s;
      }
    }
    return best;
  }

  Params params_;
  std::deque<Pending> pending_;
  std::deque<std::pair<ros::Time, Sweep>> sweeps_;
  bool have_image_ = false;
  ros::Time last_image_stamp_;
};

}  // namespace lidar_stereo_fusion
