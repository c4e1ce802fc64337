#include "bag_outputs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "bag_files.h"
#include "lidar_stereo_fusion/core/depth.h"
#include "lidar_stereo_fusion/io/pcd.h"
#include "lidar_stereo_fusion/ros/conversions.h"
#include "lidar_stereo_fusion/ros/frame_input.h"
#include "lidar_stereo_fusion/ros/output_publisher.h"

namespace fs = std::filesystem;

namespace lidar_stereo_fusion {

namespace {

std::string format(const char* fmt, double v) {
  char text[64];
  std::snprintf(text, sizeof(text), fmt, v);
  return text;
}

/// A CSV field: quoted when it holds a comma, quote or line break.
std::string csvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"') out += '"';
    out += c == '\n' ? ' ' : c;
  }
  return out + "\"";
}

/// A PNG encoded in memory and written through a temporary name (bag_files.h): the temporary
/// file never ends in .png, and a failure names the reason.
void writePngAtomically(const std::string& path, const cv::Mat& image) {
  std::vector<uchar> bytes;
  try {
    if (!cv::imencode(".png", image, bytes)) throw std::runtime_error("the encoder refused it");
  } catch (const cv::Exception& e) {
    throw std::runtime_error("cannot encode " + path + ": " + e.what());
  }
  writeBytesAtomically(path, std::string(bytes.begin(), bytes.end()));
}

/// [0, 1] (or px) * scale as uint16, 0 = none (negative, NaN).
cv::Mat scaledUint16(const cv::Mat1f& image, double scale) {
  cv::Mat_<uint16_t> raw(image.size(), uint16_t{0});
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const float v = image(y, x);
      if (!std::isfinite(v) || v <= 0.f) continue;
      raw(y, x) = static_cast<uint16_t>(std::clamp(std::round(v * scale), 1.0, 65535.0));
    }
  }
  return raw;
}

}  // namespace

FusedSet fuseSet(const InputMatch& match, const Eigen::Isometry3d& T_cam_lidar,
                 FusionPipeline& pipeline, const NodeParams& node_params,
                 const tf2::BufferCore& tf) {
  EgoMotionTf ego_motion;
  ego_motion.buffer = &tf;  // the bag's: no wait
  PreparedFrame frame = prepareFusionInput(match, T_cam_lidar, node_params, ego_motion, "");
  if (!frame.accepted()) throw std::runtime_error(frame.reason);
  FusedSet out;
  try {
    out.result = pipeline.process(frame.input);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("fusion failed: ") + e.what());
  }
  out.report = std::move(frame.report);
  out.camera = frame.input.camera;
  out.left = frame.input.left;
  out.depth = outputDepth(out.result, out.camera, node_params.max_output_depth);
  return out;
}

std::string framesCsvHeader() {
  return "stamp,status,reason,sweep_stamp,sweep_offset_s,conversion_ms,projection_ms,"
         "upsampling_ms,patchmatch_ms,depth_ms,total_ms,cloud_points,prior_coverage,coverage,"
         "rings,ring_method,method\n";
}

std::string okRow(const ros::Time& stamp, const InputMatch& match, const FusedSet& set,
                  const std::string& method) {
  const FrameStats& s = set.result.stats;
  return stampName(stamp) + ",ok,," + stampName(match.sweep_stamp) + "," +
         format("%.6f", (match.sweep_stamp - match.image_stamp).toSec()) + "," +
         format("%.1f", set.report.conversion_ms) + "," + format("%.1f", s.projection_ms) + "," +
         format("%.1f", s.upsampling_ms) + "," + format("%.1f", s.patchmatch_ms) + "," +
         format("%.1f", s.depth_ms) + "," + format("%.1f", s.total_ms) + "," +
         std::to_string(set.report.cloud_points) + "," + format("%.4f", s.prior_coverage) + "," +
         format("%.4f", s.output_coverage) + "," + std::to_string(set.report.rings.rings) + "," +
         ringSourceName(set.report.rings.source) + "," + method + "\n";
}

std::string notOkRow(const ros::Time& stamp, const std::string& status, const std::string& reason) {
  return stampName(stamp) + "," + status + "," + csvField(reason) + ",,,,,,,,,,,,,,\n";
}

void writeFileAtomically(const std::string& path, const std::string& text) {
  writeBytesAtomically(path, text);
}

OutputWriter::OutputWriter(const OutputOptions& options, const NodeParams& node_params)
    : options_(options), node_params_(node_params) {
  fs::create_directories(options_.dir);
  if (options_.disparity) fs::create_directories(fs::path(options_.dir) / "disparity");
  if (options_.confidence) fs::create_directories(fs::path(options_.dir) / "confidence");
  if (options_.cloud) fs::create_directories(fs::path(options_.dir) / "cloud");
  if (!options_.out_bag.empty()) {  // renamed into place by close()
    bag_ = std::make_unique<rosbag::Bag>(tempPath(options_.out_bag), rosbag::bagmode::Write);
  }
}

OutputWriter::~OutputWriter() {
  // Not closed: an error ends the run, and the unfinished --out-bag stays under its temporary
  // name, which the next run removes.
  try {
    if (bag_) bag_->close();
  } catch (...) {  // a destructor must not throw
  }
}

void OutputWriter::close() {
  if (!bag_) return;
  bag_->close();
  bag_.reset();
  fs::rename(tempPath(options_.out_bag), options_.out_bag);
}

std::string OutputWriter::depthPath(const ros::Time& stamp) const {
  return (fs::path(options_.dir) / (stampName(stamp) + ".png")).string();
}

std::string OutputWriter::cloudPath(const ros::Time& stamp) const {
  return (fs::path(options_.dir) / "cloud" / (stampName(stamp) + ".pcd")).string();
}

bool OutputWriter::complete(const ros::Time& stamp) const {
  std::error_code ec;
  const std::string name = stampName(stamp) + ".png";
  return fs::exists(depthPath(stamp), ec) &&
         (!options_.disparity || fs::exists(fs::path(options_.dir) / "disparity" / name, ec)) &&
         (!options_.cloud || fs::exists(cloudPath(stamp), ec));
}

std::string OutputWriter::topic(const std::string& relative) const {
  const auto it = options_.remaps.find(relative);
  if (it != options_.remaps.end()) return it->second;
  return options_.ns + "/" + relative;
}

void OutputWriter::write(const InputMatch& match, const ros::Time& receipt, const FusedSet& set,
                         const FusionParams& params) {
  const std::string name = stampName(match.image_stamp);
  // The depth PNG last: its presence tells --resume that the set is complete.
  if (options_.disparity) {
    writePngAtomically((fs::path(options_.dir) / "disparity" / (name + ".png")).string(),
                       scaledUint16(set.result.disparity, 256.0));  // KITTI disparity format
  }
  if (options_.confidence && !set.result.confidence.empty()) {
    writePngAtomically((fs::path(options_.dir) / "confidence" / (name + ".png")).string(),
                       scaledUint16(set.result.confidence, 65535.0));
  }
  if (options_.cloud) {
    // The points of points2 (left optical frame, coloured from the left image), x y z rgb, as
    // kitti_runner --save-pcd writes them.
    const std::string path = cloudPath(match.image_stamp);
    pcd::writeColoredPcd(tempPath(path), makeColoredCloud(set.depth, set.left, set.camera));
    fs::rename(tempPath(path), path);
  }
  // KITTI depth format: metres * 256 rounded, clamped to [1, 65535], 0 = none (as
  // kitti::writeDepthPng, encoded here to go through a temporary name).
  writePngAtomically(depthPath(match.image_stamp), scaledUint16(set.depth, 256.0));

  if (!bag_) return;
  // The node's output topics, stamped as their inputs, at the left image's bag time.
  const std_msgs::Header& header = match.images.left->header;
  const ros::Time t = receipt;
  auto info = boost::make_shared<sensor_msgs::CameraInfo>(*match.images.left_info);
  info->header = header;
  bag_->write(topic("depth/image_rect"), t, conversions::depthToMsg(set.depth, header));
  bag_->write(topic("depth/camera_info"), t, info);
  bag_->write(topic("disparity"), t,
              conversions::disparityToMsg(set.result.disparity, header, set.camera,
                                          params.patchmatch.min_disparity,
                                          params.patchmatch.max_disparity));
  bag_->write(topic("points2"), t,
              conversions::organizedCloudToMsg(set.depth, set.left, set.camera,
                                               node_params_.cloud_stride, header));
  const cv::Mat1f zeros = cv::Mat1f::zeros(set.camera.height, set.camera.width);
  bag_->write(
      topic("lidar_disparity"), t,
      conversions::floatImageToMsg(set.result.prior.empty() ? zeros : set.result.prior, header));
  bag_->write(topic("confidence"), t,
              conversions::floatImageToMsg(
                  set.result.confidence.empty() ? zeros : set.result.confidence, header));
}

}  // namespace lidar_stereo_fusion
