// The one frame path of the live node and bag_runner: from the messages of one matched set (stereo
// pair, camera_infos, sweep) to the core pipeline's input and the frame's report, or a rejection
// with its reason. FusionWorker::processMatch (live; TF from tf2_ros, waited for up to
// ~tf_timeout) and fuseSet (bag_runner; TF from the bag) both call prepareFusionInput(), so a
// frame is converted, checked, given rings and moved to the image stamp in one place.
//
// What stays with the callers: the LiDAR -> camera extrinsics (each names its own TF source in
// the error), the core pipeline (FusionPipeline::process) and what is done with a rejection or a
// warning (the node counts and logs them throttled; bag_runner writes them to frames.csv and
// stderr).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <ros/time.h>
#include <tf2/buffer_core.h>
#include <Eigen/Geometry>

#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/ros/stereo_sync.h"

namespace lidar_stereo_fusion {

/// What the ROS layer knows of a frame beyond the core's result (FusionStats, frames.csv).
struct FrameReport {
  std::string method;
  double conversion_ms = 0;  ///< messages -> pipeline input, ego-motion included (the node adds
                             ///< its output conversion before publishing FusionStats)
  int cloud_points = 0;      ///< finite points of the sweep given to the pipeline
  int invalid_points = 0;    ///< points dropped: NaN / inf, or beyond kMaxCoordinate
  RingRecovery rings;
  std::string point_time_field = "none";  ///< conversions::pointTimeFieldName
  int bad_times = 0;                      ///< points whose time was not used
  bool motion_compensated = false;        ///< moved to the image stamp through ~fixed_frame
  double motion_ms = 0;                   ///< TF sampling and moving the points
  std::string motion_failure;  ///< why ego-motion compensation failed (~fixed_frame set), or empty
};

/// A warning about a frame (processed anyway, unless the frame is also rejected).
struct FrameNote {
  std::string kind;  ///< a fixed word (the throttle key): "encodings", "rings", "time", "egomotion"
  std::string text;  ///< the warning, naming the topic and the stamp
};

/// Why a matched set gives the pipeline no input.
enum class FrameRejection {
  kNone,         ///< accepted
  kConversion,   ///< a message cannot be converted (encoding, sizes, calibration, cloud layout)
  kNoPoints,     ///< the sweep has no point, or none that is finite and within kMaxCoordinate
  kNoEgoMotion,  ///< ego-motion not on TF with ~motion_failure: skip
};

/// The fixed word of a rejection ("convert", "nan", "egomotion"; "" for kNone): the node's
/// throttle key.
const char* rejectionKind(FrameRejection rejection);

/// The outcome of prepareFusionInput().
struct PreparedFrame {
  FrameRejection rejection = FrameRejection::kNone;
  std::string reason;  ///< why rejected, naming the problem and the stamp; empty when accepted
  FusionInput input;   ///< accepted: what FusionPipeline::process takes
  FrameReport report;  ///< as far as the frame got (method: the caller's)
  std::vector<FrameNote> notes;  ///< warnings, in the order they arose
  bool accepted() const { return rejection == FrameRejection::kNone; }
};

/// Where the ego-motion is read when ~fixed_frame is set.
struct EgoMotionTf {
  const tf2::BufferCore* buffer = nullptr;  ///< null: none (compensation then fails, saying so)
  /// Called once before the lookups with the latest instant they need: waits until `buffer` can
  /// give `lidar_frame` in `fixed_frame` then, or throws tf2::TransformException saying why not
  /// (the live node waits up to ~tf_timeout). Empty: no wait (a bag's buffer holds all it will).
  std::function<void(const std::string& fixed_frame, const std::string& lidar_frame,
                     const ros::Time& latest)>
      wait;
};

/// Prepares the pipeline's input from the messages of `match`, with the LiDAR -> left camera
/// transform `T_cam_lidar` (taken at extrinsicsStamp()) and the node parameters `params`
/// (max_point_time, num_rings, fixed_frame, motion_samples, motion_failure):
///  1. converts the stereo pair and the camera_infos (conversions::stereoPairToCore,
///     stereoCameraFromInfo; the images must have their camera_info's size) and the sweep
///     (conversions::cloudFromMsg): rejected (kConversion) when any cannot be;
///  2. rejects a sweep without a finite point (kNoPoints);
///  3. gives every point a ring (ensureRings; a note when no method was plausible) and notes
///     point times that were not used;
///  4. with params.fixed_frame set, moves the points to the image stamp (compensateSweep, TF from
///     `tf`); on a TF failure: rejected (kNoEgoMotion) with ~motion_failure: skip, else a note and
///     the frame goes on uncompensated. report.motion_failure says why in both cases.
/// `cloud_topic` names the sweep's topic in the texts (empty: not named). Other exceptions
/// (e.g. from ensureRings on num_rings < 1, which NodeParams::validate refuses) propagate.
PreparedFrame prepareFusionInput(const InputMatch& match, const Eigen::Isometry3d& T_cam_lidar,
                                 const NodeParams& params, const EgoMotionTf& tf,
                                 const std::string& cloud_topic);

}  // namespace lidar_stereo_fusion
