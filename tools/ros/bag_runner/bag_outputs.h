// What bag_runner writes for one processed image set: the fusion of a matched set (the node's
// frame path, frame_input.h, and the core pipeline), the depth PNG and the optional files, the
// row of frames.csv and the messages of --out-bag. Separate from the bag reading (bag_runner.cpp)
// so that each stays short.
#pragma once

#include <map>
#include <memory>
#include <string>

#include <rosbag/bag.h>
#include <Eigen/Geometry>

#include "bag_pairing.h"
#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/ros/frame_input.h"
#include "lidar_stereo_fusion/ros/node_support.h"

#include <tf2/buffer_core.h>

namespace lidar_stereo_fusion {

/// One processed set: the core result and what the ROS layer knows of it.
struct FusedSet {
  StereoCamera camera;
  cv::Mat left;  ///< left image as the pipeline saw it
  FusionResult result;
  cv::Mat1f depth;     ///< the node's published depth [m] (outputDepth), 0 = none
  FrameReport report;  ///< of prepareFusionInput; report.motion_failure: ~fixed_frame set and
                       ///< processed uncompensated, why (method: empty, okRow takes it)
};

/// Runs the fusion on a matched set with LiDAR -> camera `T_cam_lidar` through the node's frame
/// path (prepareFusionInput: conversions, ring recovery, ego-motion compensation through
/// node_params.fixed_frame from `tf`, the bag's /tf and /tf_static), then the core pipeline and
/// outputDepth, as the node's worker does. Throws std::runtime_error with the frame path's reason
/// of a rejection (conversion, no finite point, missing ego-motion with ~motion_failure: skip) or
/// naming a pipeline failure.
FusedSet fuseSet(const InputMatch& match, const Eigen::Isometry3d& T_cam_lidar,
                 FusionPipeline& pipeline, const NodeParams& node_params,
                 const tf2::BufferCore& tf);

/// Which files to write besides the depth PNG.
struct OutputOptions {
  std::string dir;
  bool disparity = false, confidence = false, cloud = false;
  std::string out_bag;                        ///< empty: none
  std::string ns = "/fusion";                 ///< namespace of the --out-bag topics
  std::map<std::string, std::string> remaps;  ///< output name (relative) -> topic
};

/// frames.csv: the header line and the rows.
std::string framesCsvHeader();
std::string okRow(const ros::Time& stamp, const InputMatch& match, const FusedSet& set,
                  const std::string& method);
std::string notOkRow(const ros::Time& stamp, const std::string& status, const std::string& reason);

/// Writes the files of one set (each to a temporary name, then renamed: a killed run leaves no
/// half-written file; bag_files.h) and, with --out-bag, its messages (into a temporary bag renamed
/// by close()). The PCDs of --cloud have the layout of points2 and kitti_runner --save-pcd.
class OutputWriter {
 public:
  OutputWriter(const OutputOptions& options, const NodeParams& node_params);
  ~OutputWriter();
  /// DIR/<stamp>.png: the depth PNG of the set stamped `stamp`.
  std::string depthPath(const ros::Time& stamp) const;
  /// DIR/cloud/<stamp>.pcd.
  std::string cloudPath(const ros::Time& stamp) const;
  /// Whether every file asked for the set stamped `stamp` exists (the depth PNG, and the
  /// disparity PNG and PCD when asked; a set without confidence writes none): --resume keeps it.
  bool complete(const ros::Time& stamp) const;
  void write(const InputMatch& match, const ros::Time& receipt, const FusedSet& set,
             const FusionParams& params);
  void close();

 private:
  std::string topic(const std::string& relative) const;
  OutputOptions options_;
  NodeParams node_params_;
  std::unique_ptr<rosbag::Bag> bag_;
};

/// Writes `text` to `path` through a temporary file and a rename. Throws naming the path and why.
void writeFileAtomically(const std::string& path, const std::string& text);

}  // namespace lidar_stereo_fusion
