#include "lidar_stereo_fusion/ros/bag_outputs.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <opencv2/imgcodecs.hpp>

#include "lidar_stereo_fusion/core/depth.h"
#include "lidar_stereo_fusion/io/kitti.h"
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

/// A temporary name beside `path` (same folder, so the rename is atomic).
std::string tempPath(const std::string& path) { return path + ".tmp" + std::to_string(::getpid()); }

void writeImageAtomically(const std::string& path, const cv::Mat& image) {
  const std::string tmp = tempPath(path) + ".png";
  if (!cv::imwrite(tmp, image)) throw std::runtime_error("cannot write " + tmp);
  fs::rename(tmp, path);
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
  const std::string tmp = tempPath(path);
  {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    if (!out.flush()) throw std::runtime_error("cannot write " + tmp);
  }
  fs::rename(tmp, path);
}

OutputWriter::OutputWriter(const OutputOptions& options, const NodeParams& node_params)
    : options_(options), node_params_(node_params) {
  fs::create_directories(options_.dir);
  if (options_.disparity) fs::create_directories(fs::path(options_.dir) / "disparity");
  if (options_.confidence) fs::create_directories(fs::path(options_.dir) / "confidence");
  if (options_.cloud) fs::create_directories(fs::path(options_.dir) / "cloud");
  if (!options_.out_bag.empty()) {
    bag_ = std::make_unique<rosbag::Bag>(options_.out_bag, rosbag::bagmode::Write);
  }
}

OutputWriter::~OutputWriter() {
  try {
    close();
  } catch (...) {  // a destructor must not throw; close() reports when called explicitly
  }
}

void OutputWriter::close() {
  if (bag_) bag_->close();
  bag_.reset();
}

std::string OutputWriter::depthPath(const ros::Time& stamp) const {
  return (fs::path(options_.dir) / (stampName(stamp) + ".png")).string();
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
    writeImageAtomically((fs::path(options_.dir) / "disparity" / (name + ".png")).string(),
                         scaledUint16(set.result.disparity, 256.0));  // KITTI disparity format
  }
  if (options_.confidence && !set.result.confidence.empty()) {
    writeImageAtomically((fs::path(options_.dir) / "confidence" / (name + ".png")).string(),
                         scaledUint16(set.result.confidence, 65535.0));
  }
  if (options_.cloud) {
    LidarCloud points;  // left optical frame; intensity = grey value of the left image
    for (const ColoredPoint& p : makeColoredCloud(set.depth, set.left, set.camera)) {
      LidarPoint q;
      q.x = p.x;
      q.y = p.y;
      q.z = p.z;
      q.intensity = (p.r + p.g + p.b) / 3.f;
      points.push_back(q);
    }
    const std::string path = (fs::path(options_.dir) / "cloud" / (name + ".pcd")).string();
    pcd::writePcd(tempPath(path), points);
    fs::rename(tempPath(path), path);
  }
  const std::string depth_path = depthPath(match.image_stamp);
  kitti::writeDepthPng(tempPath(depth_path) + ".png", set.depth);
  fs::rename(tempPath(depth_path) + ".png", depth_path);

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
