// What bag_runner reads, checked before any work: the bags (each problem said as what it is), the
// remaps (validated against the node's names, topics resolved as ROS resolves them for a node in
// the root namespace), the input topics against the recording (present, of a usable type; an
// image topic recorded only as <topic>/compressed is read there) and the time window.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include <rosbag/bag.h>

#include "bag_pairing.h"

namespace lidar_stereo_fusion {

/// Opens `path` for reading, or throws std::runtime_error saying what it is instead: missing, a
/// folder (a ROS 2 bag folder named as such), empty, unreadable, not a ROS 1 bag (a ROS 2 .db3 or
/// .mcap named), or a ROS 1 bag rosbag cannot open (truncated by an interrupted recording:
/// `rosbag reindex`).
std::unique_ptr<rosbag::Bag> openBag(const std::string& path);

/// Applies one NAME:=TOPIC argument: NAME one of the node's inputs (left/image_rect_color, ...) or
/// outputs (depth/image_rect, ...; for --out-bag), TOPIC a valid ROS name, resolved in the root
/// namespace ("zed/left" -> "/zed/left"). Throws UsageError naming an unknown NAME (and the
/// nearest known one), a private or invalid TOPIC.
void applyRemap(const std::string& argument, BagTopics& topics,
                std::map<std::string, std::string>& output_remaps);

/// The input topics `asked` checked against the recording: each must hold messages of a usable
/// type (images: sensor_msgs/Image or CompressedImage; camera_infos; PointCloud2). An image topic
/// the recording lacks but has as <topic>/compressed is read there (said in `notes`). Throws
/// std::runtime_error naming what is missing or of the wrong type, the remap to use and the
/// recording's topics with their types; also when there is no /tf_static or /tf.
BagTopics resolveTopics(const std::vector<std::unique_ptr<rosbag::Bag>>& bags,
                        const BagTopics& asked, std::vector<std::string>* notes);

/// The sets reported: those whose left image was recorded in [from, to).
struct TimeWindow {
  ros::Time begin;  ///< start of the recording
  ros::Time from = ros::TIME_MIN, to = ros::TIME_MAX;
  int sets = 0;  ///< left images in the window
};

/// The window of --start / --end (seconds after the recording's start, < 0 = open). Throws
/// std::runtime_error when it holds no left image and `allow_empty` is false, naming the
/// recording's length and where its left images are.
TimeWindow timeWindow(const std::vector<std::unique_ptr<rosbag::Bag>>& bags,
                      const std::string& left_topic, double start, double end, bool allow_empty);

}  // namespace lidar_stereo_fusion
