#include "lidar_stereo_fusion/ros/fusion_worker.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <vector>

#include <tf2_eigen/tf2_eigen.h>
#include <boost/bind/bind.hpp>

#include "lidar_stereo_fusion/io/process_memory.h"
#include "lidar_stereo_fusion/io/simd_env.h"
#include "lidar_stereo_fusion/ros/ego_motion.h"
#include "lidar_stereo_fusion/ros/ros_params.h"

namespace lidar_stereo_fusion {

namespace {

/// The node parameters under `pnh`, each problem logged as an error naming the parameter.
NodeParams readNodeParamsLogged(const ros::NodeHandle& pnh, const std::string& name) {
  std::vector<std::string> errors;
  NodeParams p = ros_params::readNodeParams(pnh, &errors);
  for (const auto& e : errors) ROS_ERROR_STREAM("[" << name << "] " << e);
  return p;
}

}  // namespace

FusionWorker::FusionWorker(const ros::NodeHandle& nh, const ros::NodeHandle& pnh,
                           const std::string& name)
    : nh_(nh),
      pnh_(pnh),
      name_(name),
      node_params_(readNodeParamsLogged(pnh, name)),
      log_(name, node_params_.log_throttle_period),
      gate_(nh, pnh, node_params_, counters_, log_),
      outputs_(nh, pnh, name, node_params_, counters_, gate_),
      tf_listener_(tf_buffer_) {
  // Core parameters: the defaults of the structs, overridden by what is on the parameter server.
  std::vector<std::string> errors;
  FusionParams params = ros_params::readParams(pnh_, FusionParams(), &errors);
  for (const auto& e : errors) ROS_ERROR_STREAM("[" << name_ << "] " << e);
  try {
    params.validate();
  } catch (const std::exception& e) {
    ROS_ERROR_STREAM("[" << name_ << "] parameters rejected (" << e.what()
                         << "); using the defaults of FusionParams");
    params = FusionParams();
  }
  params_ = params;
  live_node_ = frame_node_ = node_params_;
  std::string simd_warning;  // the SIMD path is no parameter: LSF_SIMD, kept by reconfigure
  params_.patchmatch.simd_path = simdPathFromEnvironment(&simd_warning);
  if (!simd_warning.empty()) ROS_WARN_STREAM("[" << name_ << "] " << simd_warning);
  std::string memory_problem;  // process-wide: the manager's other nodelets keep theirs too
  if (node_params_.keep_freed_memory && !keepFreedMemory(&memory_problem)) {
    ROS_WARN_STREAM("[" << name_ << "] keep_freed_memory: " << memory_problem);
  }
  ros_params::writeParams(pnh_, params_);

  // Live parameters: start from the values just read, then follow dynamic_reconfigure.
  reconfigure_server_ =
      std::make_unique<dynamic_reconfigure::Server<FusionConfig>>(reconfigure_mutex_, pnh_);
  reconfigure_server_->updateConfig(ros_params::toConfig(params_, live_node_));
  reconfigure_server_->setCallback(boost::bind(&FusionWorker::reconfigureCb, this,
                                               boost::placeholders::_1, boost::placeholders::_2));

  worker_ = std::thread(&FusionWorker::workerLoop, this);
  outputs_.advertise();  // last: connect callbacks may subscribe right away

  std::string drivers;  // set by launch files that start drivers (zed_vls128.launch)
  if (pnh_.getParam("drivers", drivers) && !drivers.empty()) {
    ROS_INFO_STREAM("[" << name_ << "] drivers: " << drivers);
  }
  ROS_INFO_STREAM("[" << name_ << "] method " << methodName(params_.method) << ", "
                      << (node_params_.approximate_sync ? "approximate" : "exact")
                      << " image sync, sweeps matched within " << node_params_.max_time_offset
                      << " s; waiting for a subscriber on the outputs (e.g. "
                      << topicName("depth/image_rect") << "), then subscribing to the inputs "
                      << gate_.inputTopics());
}

FusionWorker::~FusionWorker() {
  outputs_.shutdown();  // unsubscribes the gate
  gate_.stop();
  if (worker_.joinable()) worker_.join();
}

void FusionWorker::reconfigureCb(FusionConfig& config, uint32_t /*level*/) {
  FusionParams current;
  NodeParams current_node;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    current = params_;
    current_node = live_node_;
  }
  FusionParams candidate;
  NodeParams candidate_node = current_node;
  try {
    candidate = ros_params::fromConfig(config, &candidate_node);
    candidate.patchmatch.simd_path = current.patchmatch.simd_path;
    candidate.validate();
    candidate_node.validate();
  } catch (const std::exception& e) {
    // Refused as a whole: the response (and `dynparam get`) carry the values in force.
    const std::string asked = ros_params::describeRequest(current, current_node, config);
    config = ros_params::toConfig(current, current_node);
    ROS_ERROR_STREAM("[" << name_ << "] parameter change refused: " << e.what() << "; asked "
                         << asked << "; every parameter keeps the value in force");
    return;
  }
  std::string changes = ros_params::describeChanges(current, candidate);
  const std::string node_changes = ros_params::describeChanges(current_node, candidate_node);
  if (!node_changes.empty()) changes += (changes.empty() ? "" : ", ") + node_changes;
  if (changes.empty()) return;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    params_ = candidate;
    live_node_ = candidate_node;
    params_changed_ = true;
  }
  ros_params::writeParams(pnh_, candidate);
  ROS_INFO_STREAM("[" << name_ << "] parameters changed: " << changes);
}

void FusionWorker::workerLoop() {
  if (node_params_.worker_nice > 0) {
    // Linux: the nice value is per thread and inherited by the threads this one creates (OpenMP).
    const auto tid = static_cast<id_t>(syscall(SYS_gettid));
    errno = 0;
    const int current = getpriority(PRIO_PROCESS, tid);
    if (errno != 0 || setpriority(PRIO_PROCESS, tid, current + node_params_.worker_nice) != 0) {
      ROS_WARN_STREAM("[" << name_ << "] could not lower the priority of the worker thread: "
                          << std::strerror(errno));
    }
  }
  FusionParams params;
  {
    std::lock_guard<std::mutex> lock(params_mutex_);
    params = params_;
    params_changed_ = false;
  }
  FusionPipeline pipeline(params);
  RateGovernor governor(params);
  governor_dropped_ = counters_.dropped;
  while (true) {
    // 20 ms: how often sets that waited ~max_sweep_wait are decided, and stop() noticed.
    boost::optional<InputMatch> job = gate_.next(std::chrono::milliseconds(20));
    if (gate_.stopped()) return;
    if (!job) continue;
    {
      std::lock_guard<std::mutex> lock(params_mutex_);
      if (params_changed_) {
        pipeline.setParams(params_);  // validated in reconfigureCb
        if (governor.step() > 0) outputs_.setSearchEffort(false, "as configured");
        governor.rebase(params_);  // the new search, from its first step
        frame_node_ = live_node_;
        outputs_.setLiveParams(frame_node_);
        params_changed_ = false;
      }
    }
    try {
      const auto start = std::chrono::steady_clock::now();
      const uint32_t processed = counters_.processed;
      processMatch(*job, pipeline);
      if (frame_node_.keep_rate && counters_.processed != processed) {
        const std::chrono::duration<double, std::milli> busy =
            std::chrono::steady_clock::now() - start;
        keepRate(governor, pipeline, busy.count());
      }
    } catch (const std::exception& e) {  // last line of defence: the worker thread must not die
      ++counters_.errors;
      log_.log(
          ThrottledLog::Level::kError, "pipeline", "error",
          "frame at " + stampText(job->image_stamp) + " failed: " + e.what() + "; frame skipped");
    }
  }
}

void FusionWorker::processMatch(const InputMatch& match, FusionPipeline& pipeline) {
  Eigen::Isometry3d T_cam_lidar;
  if (!lookupExtrinsics(match, T_cam_lidar)) return;
  EgoMotionTf tf;
  tf.buffer = &tf_buffer_;
  tf.wait = [this](const std::string& fixed_frame, const std::string& lidar_frame,
                   const ros::Time& latest) { waitForTf(fixed_frame, lidar_frame, latest); };
  PreparedFrame frame = prepareFusionInput(match, T_cam_lidar, frame_node_, tf, topicName(kCloud));
  reportFrame(frame);
  if (!frame.accepted()) return;

  FusionResult result;
  try {
    result = pipeline.process(frame.input);
  } catch (const std::exception& e) {
    ++counters_.errors;
    log_.log(ThrottledLog::Level::kError, "pipeline", "error",
             "fusion failed on the frame at " + stampText(match.image_stamp) + ": " + e.what() +
                 "; frame skipped");
    return;
  }
  ROS_DEBUG_STREAM("[" << name_ << "] processed " << stampText(match.image_stamp) << " in "
                       << result.stats.total_ms << " ms");
  frame.report.method = methodName(pipeline.params().method);
  outputs_.publish(match, frame.input.camera, frame.input.left, result, pipeline.params(),
                   frame.report);
}

void FusionWorker::keepRate(RateGovernor& governor, FusionPipeline& pipeline, double busy_ms) {
  const uint32_t dropped = counters_.dropped;
  const uint32_t new_drops = dropped - governor_dropped_;
  governor_dropped_ = dropped;
  const int before = governor.step();
  if (!governor.observe(new_drops, gate_.inputPeriod(), busy_ms)) return;
  pipeline.setParams(governor.params());
  const bool reduced = governor.step() > 0;
  const std::string effort = governor.current().describe() + " (step " +
                             std::to_string(governor.step()) + " of " +
                             std::to_string(governor.steps() - 1) + ")";
  outputs_.setSearchEffort(reduced, effort);
  const std::string text = "keep_rate: " + governor.reason() + "; from now on " + effort +
                           (reduced ? " (set keep_rate false to keep the configured search)" : "");
  if (governor.step() > before) {
    ROS_WARN_STREAM("[" << name_ << "] " << text);
  } else {
    ROS_INFO_STREAM("[" << name_ << "] " << text);
  }
}

bool FusionWorker::lookupExtrinsics(const InputMatch& match, Eigen::Isometry3d& T_cam_lidar) {
  const std::string& camera_frame = match.images.left->header.frame_id;
  const std::string& lidar_frame = match.sweep->header.frame_id;
  // At the sweep stamp, or at the image stamp the points are moved to with ~fixed_frame; a short
  // timeout bounds the wait (worker thread only).
  const ros::Time stamp =
      extrinsicsStamp(frame_node_.fixed_frame, match.sweep_stamp, match.image_stamp);
  try {
    T_cam_lidar = tf2::transformToEigen(tf_buffer_.lookupTransform(
        camera_frame, lidar_frame, stamp, ros::Duration(frame_node_.tf_timeout)));
    return true;
  } catch (const tf2::TransformException& e) {
    ++counters_.tf_failures;
    log_.warn(kCloud, "tf",
              "no transform from '" + lidar_frame + "' (" + topicName(kCloud) + ") to '" +
                  camera_frame + "' (" + topicName(kLeftImage) + ") at " +
                  (frame_node_.fixed_frame.empty() ? "sweep stamp " : "image stamp ") +
                  stampText(stamp) + " within " + std::to_string(frame_node_.tf_timeout) +
                  " s: " + e.what() + "; frame skipped");
    return false;
  }
}

void FusionWorker::waitForTf(const std::string& fixed_frame, const std::string& lidar_frame,
                             const ros::Time& latest) {
  std::string why;
  if (!tf_buffer_.canTransform(fixed_frame, lidar_frame, latest,
                               ros::Duration(frame_node_.tf_timeout), &why)) {
    throw tf2::TransformException("no transform from '" + lidar_frame + "' to '" + fixed_frame +
                                  "' at " + stampText(latest) + " within " +
                                  std::to_string(frame_node_.tf_timeout) + " s: " + why);
  }
}

void FusionWorker::reportFrame(const PreparedFrame& frame) {
  if (!frame.report.motion_failure.empty()) ++counters_.motion_failures;
  for (const FrameNote& note : frame.notes) {
    if (note.kind != "encodings") {
      log_.warn(kCloud, note.kind, note.text);
    } else if (note.text != mixed_encodings_said_) {  // said once per pair of encodings
      ROS_WARN_STREAM("[" << name_ << "] " << note.text);
      mixed_encodings_said_ = note.text;
    }
  }
  if (frame.accepted()) return;
  if (frame.rejection != FrameRejection::kNoEgoMotion) ++counters_.invalid;
  log_.warn(frame.rejection == FrameRejection::kConversion ? "input set" : kCloud,
            rejectionKind(frame.rejection), frame.reason + "; frame skipped");
}

}  // namespace lidar_stereo_fusion
