#include "lidar_stereo_fusion/ros/frame_input.h"

#include <algorithm>
#include <chrono>
#include <utility>

#include <tf2/exceptions.h>

#include "lidar_stereo_fusion/ros/conversions.h"
#include "lidar_stereo_fusion/ros/ego_motion.h"

namespace lidar_stereo_fusion {

namespace {

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

/// "topic: " before a text about the sweep, or nothing when the topic is not known.
std::string onTopic(const std::string& topic) { return topic.empty() ? "" : topic + ": "; }

std::string sizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

/// Step 1: the messages as core types. False (and `frame` rejected) when one cannot be converted.
bool convertMessages(const InputMatch& match, const NodeParams& params, PreparedFrame& frame,
                     conversions::CloudConversion& cloud) {
  const ImageSet& set = match.images;
  FusionInput& input = frame.input;
  std::string pair_note;
  try {
    conversions::stereoPairToCore(set.left, set.right, input.left, input.right, &pair_note);
    input.camera = conversions::stereoCameraFromInfo(*set.left_info, *set.right_info);
    if (input.left.cols != input.camera.width || input.left.rows != input.camera.height) {
      throw conversions::ConversionError(
          "the images are " + sizeText(input.left.cols, input.left.rows) +
          " but their camera_infos " + sizeText(input.camera.width, input.camera.height));
    }
    cloud = conversions::cloudFromMsg(*match.sweep, params.max_point_time);
  } catch (const std::exception& e) {  // ConversionError, and anything OpenCV lets through
    frame.rejection = FrameRejection::kConversion;
    frame.reason =
        "cannot convert the input set at " + stampText(match.image_stamp) + ": " + e.what();
    return false;
  }
  if (!pair_note.empty()) frame.notes.push_back({"encodings", pair_note});
  return true;
}

/// Step 2: a sweep without a finite point. True (and `frame` rejected) when it is one.
bool rejectEmptySweep(const InputMatch& match, const conversions::CloudConversion& cloud,
                      const std::string& cloud_topic, PreparedFrame& frame) {
  if (!cloud.cloud.empty()) return false;
  frame.rejection = FrameRejection::kNoPoints;
  const std::string sweep = "the sweep at " + stampText(match.sweep_stamp);
  if (cloud.total_points == 0) {
    frame.reason = onTopic(cloud_topic) + sweep + " has no points";
    return true;
  }
  frame.reason = onTopic(cloud_topic) + "none of the " + std::to_string(cloud.total_points) +
                 " points of " + sweep + " is finite and within 10 km (" +
                 std::to_string(cloud.non_finite) + " NaN / inf, " +
                 std::to_string(cloud.implausible) + " beyond 10 km)";
  return true;
}

/// Step 3: rings for every point, and what the point times say.
void recoverRings(const InputMatch& match, const NodeParams& params, const std::string& cloud_topic,
                  conversions::CloudConversion& cloud, PreparedFrame& frame) {
  FrameReport& report = frame.report;
  // The ring field if plausible, else the offline sweep-order rule, else the beams found in the
  // cloud (beam model), else elevation bands; each checked (core/ring_recovery.h).
  report.rings = ensureRings(cloud.cloud, cloud.has_ring, params.num_rings);
  if (!report.rings.plausible) {
    frame.notes.push_back(
        {"rings", onTopic(cloud_topic) + "no plausible scan lines in the sweep at " +
                      stampText(match.sweep_stamp) + " (" + report.rings.fallbacks + "); using " +
                      std::to_string(report.rings.rings) + " rings by " +
                      ringSourceName(report.rings.source) +
                      ", the prior will be coarse (a LiDAR without scan lines gives this; else "
                      "publish the driver's ring field, or set ~num_rings to the sensor's beam "
                      "count)"});
  }
  report.point_time_field = conversions::pointTimeFieldName(cloud.time_field);
  report.bad_times = cloud.bad_times;
  if (cloud.bad_times > 0) {
    frame.notes.push_back(
        {"time", onTopic(cloud_topic) + std::to_string(cloud.bad_times) + " of " +
                     std::to_string(cloud.cloud.size()) + " points of the sweep at " +
                     stampText(match.sweep_stamp) + " have a '" + report.point_time_field +
                     "' time that is NaN or more than ~max_point_time = " +
                     std::to_string(params.max_point_time) + " s from the stamp (e.g. " +
                     std::to_string(cloud.bad_time_example) +
                     " s): their time is not used (wrong unit or clock?)"});
  }
}

/// Step 4: the sweep moved to the image stamp. False (and `frame` rejected) when the ego-motion
/// is not on TF and ~motion_failure is skip.
bool compensateEgoMotion(const InputMatch& match, const NodeParams& params, const EgoMotionTf& tf,
                         conversions::CloudConversion& cloud, PreparedFrame& frame) {
  const auto start = std::chrono::steady_clock::now();
  const std::string& lidar_frame = match.sweep->header.frame_id;
  const std::vector<double> times =
      motionSampleTimes(cloud.cloud, cloud.has_time, params.motion_samples);
  try {
    if (tf.buffer == nullptr) throw tf2::TransformException("no TF to read the ego-motion from");
    // One wait for the latest instant needed; the samples are then looked up at once.
    if (tf.wait) {
      tf.wait(params.fixed_frame, lidar_frame,
              std::max(match.image_stamp, match.sweep_stamp + ros::Duration(times.back())));
    }
    compensateSweep(*tf.buffer, lidar_frame, params.fixed_frame, match.sweep_stamp,
                    match.image_stamp, times, frame.input.T_cam_lidar, frame.input.camera,
                    cloud.cloud);
    frame.report.motion_compensated = true;
  } catch (const tf2::TransformException& e) {
    frame.report.motion_failure = e.what();
    const std::string failed = "ego-motion compensation of the sweep at " +
                               stampText(match.sweep_stamp) + " to the images at " +
                               stampText(match.image_stamp) + " failed: " + e.what();
    if (params.motion_failure == "skip") {
      frame.rejection = FrameRejection::kNoEgoMotion;
      frame.reason = failed + " (~motion_failure: skip)";
      return false;
    }
    frame.notes.push_back(
        {"egomotion", failed + "; frame processed uncompensated (~motion_failure: uncompensated)"});
  }
  frame.report.motion_ms = msSince(start);
  return true;
}

}  // namespace

const char* rejectionKind(FrameRejection rejection) {
  switch (rejection) {
    case FrameRejection::kNone:
      return "";
    case FrameRejection::kConversion:
      return "convert";
    case FrameRejection::kNoPoints:
      return "nan";
    case FrameRejection::kNoEgoMotion:
      return "egomotion";
  }
  return "";
}

PreparedFrame prepareFusionInput(const InputMatch& match, const Eigen::Isometry3d& T_cam_lidar,
                                 const NodeParams& params, const EgoMotionTf& tf,
                                 const std::string& cloud_topic) {
  const auto start = std::chrono::steady_clock::now();
  PreparedFrame frame;
  frame.input.T_cam_lidar = T_cam_lidar;
  conversions::CloudConversion cloud;
  if (!convertMessages(match, params, frame, cloud)) return frame;
  if (rejectEmptySweep(match, cloud, cloud_topic, frame)) return frame;
  recoverRings(match, params, cloud_topic, cloud, frame);
  if (!params.fixed_frame.empty() && !compensateEgoMotion(match, params, tf, cloud, frame)) {
    return frame;
  }
  frame.input.cloud = std::move(cloud.cloud);
  frame.report.cloud_points = static_cast<int>(frame.input.cloud.size());
  frame.report.invalid_points = cloud.non_finite + cloud.implausible;
  frame.report.conversion_ms = msSince(start);
  return frame;
}

}  // namespace lidar_stereo_fusion
