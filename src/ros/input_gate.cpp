#include "lidar_stereo_fusion/ros/input_gate.h"

#include <sstream>
#include <utility>

#include <boost/bind/bind.hpp>

#include "lidar_stereo_fusion/ros/conversions.h"

namespace lidar_stereo_fusion {

bool RateLimiter::accept(const ros::Time& stamp) {
  if (max_rate_ <= 0.0) return true;
  // Less 10 % of the period for stamp jitter: 10 Hz input at max_rate 5 gives 5 Hz, not 3.3.
  const double min_step = 0.9 / max_rate_;
  if (!last_.isZero() && stamp >= last_ && (stamp - last_).toSec() < min_step) return false;
  last_ = stamp;
  return true;
}

InputGate::InputGate(const ros::NodeHandle& nh, const ros::NodeHandle& pnh,
                     const NodeParams& params, Counters& counters, ThrottledLog& log)
    : nh_(nh),
      pnh_(pnh),
      params_(params),
      counters_(counters),
      log_(log),
      transport_(chooseTransport(nh, pnh)),
      sub_left_image_(kLeftImage,
                      [this](const auto& n, const auto& p, const auto& t) {
                        reject(Rejection{n, "decode", p}, t, "image");
                      }),
      sub_right_image_(kRightImage,
                       [this](const auto& n, const auto& p, const auto& t) {
                         reject(Rejection{n, "decode", p}, t, "image");
                       }),
      watch_({topicName(kLeftImage), topicName(kLeftInfo), topicName(kRightImage),
              topicName(kRightInfo), topicName(kCloud)},
             params.input_timeout, log),
      // The remapped names (without /compressed): what the fix must remap.
      order_watch_({nh_.resolveName(kLeftImage), nh_.resolveName(kLeftInfo),
                    nh_.resolveName(kRightImage), nh_.resolveName(kRightInfo)}),
      rate_(params.max_rate),
      fresh_(params.fresh_wait) {
  matcher_.setParams(matcherParams(params_));
  if (!transport_.note.empty()) {
    log_.log(transport_.error ? ThrottledLog::Level::kError : ThrottledLog::Level::kInfo,
             "image_transport", "transport", transport_.note);
  }

  // Synchroniser of the image set (connected once; the filters are (un)subscribed lazily).
  it_ = std::make_shared<image_transport::ImageTransport>(nh_);
  using boost::placeholders::_1, boost::placeholders::_2, boost::placeholders::_3,
      boost::placeholders::_4;
  sync_ = std::make_unique<StereoSync>(params_, sub_left_image_, sub_left_info_, sub_right_image_,
                                       sub_right_info_,
                                       boost::bind(&InputGate::imageCb, this, _1, _2, _3, _4),
                                       boost::bind(&InputGate::syncDropCb, this, _1, _2, _3, _4));
  watchInputs();
}

/// The input watch: every input topic's arrivals (indices as in watch_'s list; the cloud's in
/// cloudCb) and, with input_timeout, its once-a-second check.
void InputGate::watchInputs() {
  sub_left_image_.registerCallback(boost::function<void(const sensor_msgs::ImageConstPtr&)>(
      [this](const auto&) { watch_.heard(0, watchNow()); }));
  sub_left_info_.registerCallback(boost::function<void(const sensor_msgs::CameraInfoConstPtr&)>(
      [this](const auto&) { watch_.heard(1, watchNow()); }));
  sub_right_image_.registerCallback(boost::function<void(const sensor_msgs::ImageConstPtr&)>(
      [this](const auto&) { watch_.heard(2, watchNow()); }));
  sub_right_info_.registerCallback(boost::function<void(const sensor_msgs::CameraInfoConstPtr&)>(
      [this](const auto&) { watch_.heard(3, watchNow()); }));
  if (params_.input_timeout > 0.0) {
    watch_timer_ = nh_.createWallTimer(ros::WallDuration(1.0), [this](const ros::WallTimerEvent&) {
      if (ros::Time::isSimTime()) {
        // Silence is measured in ROS time: a slowed bag is not silent between its frames, and a
        // bag at its end (time stopped) is not a driver gone missing. Before the first clock
        // message there is no time to measure; the watch starts from the first known time.
        if (ros::Time::now().isZero()) return;
        if (!watch_clock_started_.exchange(true)) watch_.start(watchNow());
      }
      watch_.check([this](std::size_t i) -> uint32_t {
        switch (i) {
          case 0:
            return sub_left_image_.getNumPublishers();
          case 1:
            return sub_left_info_.getSubscriber().getNumPublishers();
          case 2:
            return sub_right_image_.getNumPublishers();
          case 3:
            return sub_right_info_.getSubscriber().getNumPublishers();
          default:
            return sub_cloud_.getNumPublishers();
        }
      });
    });
  }
}

InputGate::~InputGate() {
  if (subscribed_) unsubscribe();
  stop();
}

std::string InputGate::topicName(const std::string& relative) const {
  if (relative == kLeftImage || relative == kRightImage) {
    return ImageInput::subscribedTopic(nh_, relative, transport_);
  }
  return nh_.resolveName(relative);
}

void InputGate::subscribe() {
  const uint32_t q = static_cast<uint32_t>(params_.queue_size);
  sub_left_image_.subscribe(*it_, nh_, pnh_, q, transport_);
  sub_left_info_.subscribe(nh_, kLeftInfo, q);
  sub_right_image_.subscribe(*it_, nh_, pnh_, q, transport_);
  sub_right_info_.subscribe(nh_, kRightInfo, q);
  sub_cloud_ = nh_.subscribe(kCloud, 2, &InputGate::cloudCb, this);
  subscribed_ = true;
  watch_.start(watchNow());
  ROS_DEBUG_STREAM("[" << log_.name() << "] subscribed to the inputs");
}

void InputGate::unsubscribe() {
  watch_.stop();
  sub_left_image_.unsubscribe();
  sub_left_info_.unsubscribe();
  sub_right_image_.unsubscribe();
  sub_right_info_.unsubscribe();
  sub_cloud_.shutdown();
  subscribed_ = false;
  std::lock_guard<std::mutex> lock(mutex_);
  // Sets in flight when the last subscriber leaves are dropped, and counted.
  const std::size_t pending = matcher_.clear() + (next_ ? 1 : 0);
  next_.reset();
  fresh_.clear();
  counters_.dropped += static_cast<uint32_t>(pending);
  ROS_DEBUG_STREAM("[" << log_.name() << "] no subscribers left: unsubscribed from the inputs");
}

void InputGate::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  stopped_ = true;
  ready_cv_.notify_all();
}

boost::optional<InputMatch> InputGate::next(std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  const bool was_waiting = static_cast<bool>(next_);  // the worker was busy when it came
  ready_cv_.wait_for(lock, timeout, [this] { return stop_ || static_cast<bool>(next_); });
  if (stop_) return boost::none;
  // Image sets that waited max_sweep_wait (ROS time) for a later sweep are decided here.
  InputMatcher::Events events = matcher_.poll(ros::Time::now());
  handleEvents(events, kLeftImage, ros::Time());
  if (was_waiting && next_) waitForFresher(lock);
  if (stop_) return boost::none;
  boost::optional<InputMatch> out = std::move(next_);
  next_.reset();
  return out;
}

void InputGate::waitForFresher(std::unique_lock<std::mutex>& lock) {
  const ros::Time now = ros::Time::now();
  const boost::optional<ros::Time> until = fresh_.holdUntil(now);
  if (!until) return;
  // In slices, as ROS time may be simulated; a newer set (handleEvents) ends the wait at once.
  // Twice the wait in wall time at most: a paused or slowed bag does not hold the set.
  const auto wall_limit = std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                              std::chrono::duration<double>(2.0 * (*until - now).toSec()));
  const uint64_t seen = ready_count_;
  while (!stop_ && ready_count_ == seen && ros::Time::now() < *until &&
         std::chrono::steady_clock::now() < wall_limit) {
    ready_cv_.wait_for(lock, std::chrono::milliseconds(2));
  }
}

void InputGate::reject(const Rejection& r, const ros::Time& stamp, const char* what_skipped) {
  if (r.topic == kCloud) {
    std::lock_guard<std::mutex> lock(mutex_);
    refused_sweep_stamp_ = stamp;
    refused_sweep_problem_ = r.problem;
    refused_sweep_kind_ = r.kind;
  }
  ++counters_.invalid;
  log_.warn(r.topic, r.kind,
            topicName(r.topic) + ": " + r.problem + " (stamp " + stampText(stamp) + "); " +
                what_skipped + " skipped");
}

void InputGate::detectClockJump() {
  // A bag played with --loop sends the clock back: forget the buffered stamps, or every later
  // message would count as out of order.
  const ros::Time now = ros::Time::now();
  if (!last_clock_.isZero() && now + ros::Duration(0.5) < last_clock_) {
    counters_.dropped += static_cast<uint32_t>(matcher_.clear());
    ++clock_epoch_;
    restarted(now);
    if (subscribed_) watch_.start(watchNow());  // its times are ROS times under sim time
    log_.log(ThrottledLog::Level::kInfo, "clock", "jump",
             "ROS time jumped back from " + stampText(last_clock_) + " to " + stampText(now) +
                 ": sweep and image buffers cleared (bag loop?)");
  }
  last_clock_ = now;
}

InputWatch::Clock::time_point InputGate::watchNow() {
  if (!ros::Time::isSimTime()) return InputWatch::Clock::now();
  return InputWatch::Clock::time_point(std::chrono::nanoseconds(ros::Time::now().toNSec()));
}

void InputGate::restarted(const ros::Time& now) { restart_time_ = now; }

bool InputGate::lostToRestart(const ros::Time& stamp) const {
  if (restart_time_.isZero()) return false;
  const ros::Time now = ros::Time::now();
  // The sets in flight when time restarts lose their partners (the synchroniser's queue, the
  // sweep buffer). Within a few seconds of a restart (ROS time, as the bag plays on), a set is the
  // restart's loss, not the rig's, if it was lost right after it, if it is of the first moments
  // after it (the synchroniser gives up on such a set only when its queue overflows), or if it
  // is stamped before the jump (ahead of the clock now).
  if (now > restart_time_ + ros::Duration(10.0) || now < restart_time_) return false;
  const ros::Time grace_end =
      restart_time_ + ros::Duration(1.0 + params_.max_sweep_wait + params_.max_time_offset);
  return now < grace_end || stamp <= grace_end || stamp > now + ros::Duration(0.5);
}

std::string InputGate::inputTopics() const {
  return topicName(kLeftImage) + ", " + topicName(kLeftInfo) + ", " + topicName(kRightImage) +
         ", " + topicName(kRightInfo) + ", " + topicName(kCloud);
}

bool InputGate::sweepRefusedNear(const ros::Time& image_stamp) const {
  return !refused_sweep_stamp_.isZero() && std::abs((refused_sweep_stamp_ - image_stamp).toSec()) <=
                                               params_.max_time_offset + params_.max_sweep_wait;
}

std::string InputGate::noSweepText(const ros::Time& image_stamp, bool waited) const {
  const std::string at = stampText(image_stamp);
  if (sweepRefusedNear(image_stamp)) {
    // The LiDAR is publishing: its sweep was refused (already warned about, with the reason).
    return "no usable sweep on " + topicName(kCloud) + " for the image set at " + at +
           ": the sweep at " + stampText(refused_sweep_stamp_) + " was refused (" +
           refused_sweep_problem_ + "); image set skipped";
  }
  if (waited) {  // no sweep at or after the set came in time
    return "no sweep on " + topicName(kCloud) + " stamped at or after the image set at " + at +
           " arrived within ~max_sweep_wait = " + std::to_string(params_.max_sweep_wait) +
           " s (ROS time), and none before it within ~max_time_offset = " +
           std::to_string(params_.max_time_offset) +
           " s; image set skipped (is the LiDAR publishing? raise ~max_sweep_wait if its sweeps "
           "arrive late)";
  }
  return "no sweep on " + topicName(kCloud) +
         " within ~max_time_offset = " + std::to_string(params_.max_time_offset) +
         " s of the image set at " + at +
         "; image set skipped (raise ~max_time_offset if the clocks differ)";
}

void InputGate::imageCb(const sensor_msgs::ImageConstPtr& left,
                        const sensor_msgs::CameraInfoConstPtr& left_info,
                        const sensor_msgs::ImageConstPtr& right,
                        const sensor_msgs::CameraInfoConstPtr& right_info) {
  const ros::Time stamp = left->header.stamp;
  ROS_DEBUG_STREAM("[" << log_.name() << "] image set " << stampText(stamp));
  {
    // ~max_rate: dropped here, before any work; counted, never warned about (the user asked).
    std::lock_guard<std::mutex> lock(mutex_);
    if (!rate_.accept(stamp)) {
      ++counters_.rate_limited;
      return;
    }
  }
  ImageSet set;
  set.left = left;
  set.right = right;
  set.left_info = left_info;
  set.right_info = right_info;
  set.arrival_ros = ros::Time::now();
  set.arrival_wall = std::chrono::steady_clock::now();
  set.clock_epoch = clock_epoch_;
  if (const auto rejection = checkImageSet(set)) return reject(*rejection, stamp, "image set");
  checkStereoOrder(set);
  std::lock_guard<std::mutex> lock(mutex_);
  detectClockJump();
  InputMatcher::Events events = matcher_.addImages(stamp, std::move(set), ros::Time::now());
  handleEvents(events, kLeftImage, stamp);
}

void InputGate::checkStereoOrder(const ImageSet& set) {
  // A few ms on each of the first sets only; a callback busy with it is not waited for.
  std::unique_lock<std::mutex> lock(order_mutex_, std::try_to_lock);
  if (!lock.owns_lock() || order_watch_.decided()) return;
  if (const auto warning = order_watch_.observe(set)) {
    log_.warn(kLeftImage, "swapped", *warning);
  }
}

void InputGate::syncDropCb(const sensor_msgs::ImageConstPtr& left,
                           const sensor_msgs::CameraInfoConstPtr& left_info,
                           const sensor_msgs::ImageConstPtr& right,
                           const sensor_msgs::CameraInfoConstPtr& right_info) {
  // ExactTime gave up on an incomplete set (a partner message never came with the same stamp).
  ++counters_.unmatched;
  std::string missing;
  if (!left) missing += std::string(" ") + topicName(kLeftImage);
  if (!left_info) missing += std::string(" ") + topicName(kLeftInfo);
  if (!right) missing += std::string(" ") + topicName(kRightImage);
  if (!right_info) missing += std::string(" ") + topicName(kRightInfo);
  ros::Time stamp;
  if (left)
    stamp = left->header.stamp;
  else if (right)
    stamp = right->header.stamp;
  else if (left_info)
    stamp = left_info->header.stamp;
  else if (right_info)
    stamp = right_info->header.stamp;
  bool restart;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    detectClockJump();  // the synchroniser may give up on a set before any callback saw the jump
    restart = lostToRestart(stamp);
  }
  if (restart) {
    log_.log(ThrottledLog::Level::kInfo, "image set", "restart",
             "incomplete image set at stamp " + stampText(stamp) +
                 " dropped by the exact-time synchroniser as time restarted (bag loop); missing:" +
                 missing);
    return;
  }
  log_.warn("image set", "incomplete",
            "incomplete image set at stamp " + stampText(stamp) +
                " dropped by the exact-time synchroniser; missing:" + missing +
                " (different stamps? then set ~approximate_sync true)");
}

void InputGate::cloudCb(const sensor_msgs::PointCloud2ConstPtr& cloud) {
  watch_.heard(4, watchNow());
  const ros::Time stamp = cloud->header.stamp;
  ROS_DEBUG_STREAM("[" << log_.name() << "] sweep " << stampText(stamp) << " ("
                       << static_cast<uint64_t>(cloud->width) * cloud->height << " points)");
  if (const auto rejection = checkCloud(*cloud)) return reject(*rejection, stamp, "sweep");
  std::lock_guard<std::mutex> lock(mutex_);
  detectClockJump();
  InputMatcher::Events events = matcher_.addSweep(stamp, cloud, ros::Time::now());
  handleEvents(events, kCloud, stamp);
}

void InputGate::handleEvents(InputMatcher::Events& events, const std::string& topic,
                             const ros::Time& stamp) {
  if (events.restarted) {
    counters_.dropped += static_cast<uint32_t>(events.discarded);
    ++clock_epoch_;
    restarted(ros::Time::now());
    fresh_.clear();
    std::ostringstream text;
    text << topicName(topic) << ": stamp " << stampText(stamp) << " is more than "
         << matcher_.params().restart_step
         << " s older than the last one: time restarted (bag loop?), buffers cleared";
    log_.log(ThrottledLog::Level::kInfo, topic, "restart", text.str());
  }
  if (events.out_of_order) {
    ++counters_.out_of_order;
    log_.warn(topic, "order",
              topicName(topic) + ": stamp " + stampText(stamp) +
                  " is not newer than one already received (out of order or duplicate); message "
                  "dropped");
  }
  for (std::size_t i = 0; i < events.unmatched.size(); ++i) {
    ++counters_.unmatched;
    if (lostToRestart(events.unmatched[i])) {
      log_.log(ThrottledLog::Level::kInfo, kCloud, "restart",
               "image set at " + stampText(events.unmatched[i]) +
                   " skipped: time restarted (bag loop) before its sweep came");
      continue;
    }
    const bool refused = sweepRefusedNear(events.unmatched[i]);
    const std::string kind = refused                      ? "refused " + refused_sweep_kind_
                             : events.unmatched_waited[i] ? "late"
                                                          : "unmatched";
    log_.warn(kCloud, kind, noSweepText(events.unmatched[i], events.unmatched_waited[i]));
  }
  if (events.ready.empty()) return;
  ROS_DEBUG_STREAM("[" << log_.name() << "] matched image set "
                       << stampText(events.ready.back().image_stamp) << " with sweep "
                       << stampText(events.ready.back().sweep_stamp));
  // Only the newest set is worth processing: older ones (and a set still waiting for the worker)
  // are dropped and counted, so a slow pipeline never builds a backlog.
  counters_.dropped += static_cast<uint32_t>(events.ready.size() - 1 + (next_ ? 1 : 0));
  next_ = std::move(events.ready.back());
  fresh_.ready(ros::Time::now());
  ++ready_count_;
  ready_cv_.notify_one();
}

double InputGate::inputPeriod() {
  std::lock_guard<std::mutex> lock(mutex_);
  return fresh_.period();
}

}  // namespace lidar_stereo_fusion
