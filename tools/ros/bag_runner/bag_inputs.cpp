#include "bag_inputs.h"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <tuple>

#include <ros/names.h>
#include <rosbag/view.h>

#include "lidar_stereo_fusion/io/cli.h"
#include "lidar_stereo_fusion/ros/node_support.h"

namespace fs = std::filesystem;

namespace lidar_stereo_fusion {

namespace {

std::string seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3f", s);
  return text;
}

/// The first bytes of a file, or "" when none can be read.
std::string head(const std::string& path, std::size_t n) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes(n, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(n));
  bytes.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  return bytes;
}

/// Why `path` cannot be a ROS 1 bag, or "" when it may be one.
std::string notABag(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(path, ec)) && !fs::exists(path, ec)) {
    return "no such file";
  }
  if (!fs::exists(path, ec)) return "a symbolic link to a missing file";
  if (fs::is_directory(path, ec)) {
    if (fs::exists(fs::path(path) / "metadata.yaml", ec)) {
      return "a folder: a ROS 2 bag (ros2 bag), which this ROS 1 tool cannot read (convert it with "
             "`rosbags-convert`)";
    }
    std::string bags;
    for (const auto& entry : fs::directory_iterator(path, ec)) {
      if (entry.path().extension() == ".bag") bags += " " + entry.path().string();
    }
    return "a folder, not a bag file" +
           (bags.empty() ? std::string() : " (give its bags, one --bag each:" + bags + ")");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::string("unreadable: ") + std::strerror(errno);
  if (fs::file_size(path, ec) == 0) return "an empty file (0 bytes)";
  const std::string magic = head(path, 13);
  if (magic.rfind("#ROSBAG V", 0) == 0) return "";
  if (magic.rfind("SQLite format", 0) == 0) {
    return "a SQLite file: a ROS 2 bag (.db3), which this ROS 1 tool cannot read";
  }
  if (magic.rfind("\x89MCAP", 0) == 0) return "an MCAP file, not a ROS 1 bag";
  return "not a ROS 1 bag (it does not start with #ROSBAG V2.0)";
}

/// The recording's topics with their types, "topic (type)" each.
std::map<std::string, std::string> recordedTopics(
    const std::vector<std::unique_ptr<rosbag::Bag>>& bags) {
  rosbag::View all;
  for (const auto& bag : bags) all.addQuery(*bag);
  std::map<std::string, std::string> types;
  for (const auto* c : all.getConnections()) types[c->topic] = c->datatype;
  return types;
}

std::string listed(const std::map<std::string, std::string>& types) {
  std::string out;
  for (const auto& [topic, type] : types) out += " " + topic + " (" + type + ")";
  return out.empty() ? " none" : out;
}

}  // namespace

std::unique_ptr<rosbag::Bag> openBag(const std::string& path) {
  const std::string problem = notABag(path);
  if (!problem.empty()) throw std::runtime_error("cannot read bag " + path + ": " + problem);
  auto bag = std::make_unique<rosbag::Bag>();
  try {
    bag->open(path, rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read bag " + path + ": " + e.what() +
                             " (truncated by an interrupted recording? `rosbag reindex` "
                             "may recover it)");
  }
  return bag;
}

void applyRemap(const std::string& argument, BagTopics& topics,
                std::map<std::string, std::string>& output_remaps) {
  const auto sep = argument.find(":=");
  std::string from = argument.substr(0, sep);
  const std::string to = argument.substr(sep + 2);
  if (to.empty()) throw UsageError("remap " + argument + " has no topic");
  if (!from.empty() && from[0] == '/') from = from.substr(1);  // a node in / : the same name
  std::string error;
  if (to[0] == '~' || !ros::names::validate(to, error)) {
    throw UsageError("remap " + argument + ": '" + to + "' is not a topic name" +
                     (to[0] == '~' ? " (bag_runner has no private namespace)" : ": " + error));
  }
  // As ROS resolves a relative name for a node in the root namespace.
  const std::string topic = ros::names::resolve("/", to, false);
  const std::map<std::string, std::string*> inputs = {{kLeftImage, &topics.left_image},
                                                      {kLeftInfo, &topics.left_info},
                                                      {kRightImage, &topics.right_image},
                                                      {kRightInfo, &topics.right_info},
                                                      {kCloud, &topics.cloud}};
  if (const auto input = inputs.find(from); input != inputs.end()) {
    *input->second = topic;
    return;
  }
  const auto& outputs = outputNames();
  if (std::find(outputs.begin(), outputs.end(), from) != outputs.end()) {
    output_remaps[from] = topic;
    return;
  }
  std::vector<std::string> known = inputNames();
  known.insert(known.end(), outputs.begin(), outputs.end());
  const std::string nearest = nearestName(from, known);
  std::string names;
  for (const auto& n : known) names += (names.empty() ? "" : ", ") + n;
  throw UsageError("remap " + argument + ": '" + from + "' is no input or output name" +
                   (nearest.empty() ? "" : " (did you mean " + nearest + "?)") +
                   "; the names: " + names);
}

BagTopics resolveTopics(const std::vector<std::unique_ptr<rosbag::Bag>>& bags,
                        const BagTopics& asked, std::vector<std::string>* notes) {
  const std::map<std::string, std::string> types = recordedTopics(bags);
  BagTopics out = asked;
  const std::vector<std::tuple<const char*, std::string*, std::set<std::string>>> needed = {
      {kLeftImage, &out.left_image, {"sensor_msgs/Image", "sensor_msgs/CompressedImage"}},
      {kLeftInfo, &out.left_info, {"sensor_msgs/CameraInfo"}},
      {kRightImage, &out.right_image, {"sensor_msgs/Image", "sensor_msgs/CompressedImage"}},
      {kRightInfo, &out.right_info, {"sensor_msgs/CameraInfo"}},
      {kCloud, &out.cloud, {"sensor_msgs/PointCloud2"}}};
  std::string problems;
  for (const auto& [name, topic, usable] : needed) {
    auto it = types.find(*topic);
    if (it == types.end() && usable.count("sensor_msgs/CompressedImage") &&
        types.count(*topic + "/compressed")) {
      if (notes) notes->push_back(*topic + " is recorded as " + *topic + "/compressed: read there");
      *topic += "/compressed";
      it = types.find(*topic);
    }
    if (it == types.end()) {
      problems += "; no messages on " + *topic + " (remap with " + name + ":=TOPIC)";
    } else if (!usable.count(it->second)) {
      problems += "; " + *topic + " holds " + it->second + ", but " + name + " needs " +
                  *usable.begin() + (usable.size() > 1 ? " or " + *usable.rbegin() : "");
    }
  }
  if (!problems.empty()) {
    throw std::runtime_error("the recording cannot be used: " + problems.substr(2) +
                             "; its topics:" + listed(types));
  }
  if (!types.count("/tf_static") && !types.count("/tf")) {
    throw std::runtime_error(
        "the recording has no /tf_static or /tf: no LiDAR -> camera transform; its topics:" +
        listed(types));
  }
  return out;
}

TimeWindow timeWindow(const std::vector<std::unique_ptr<rosbag::Bag>>& bags,
                      const std::string& left_topic, double start, double end, bool allow_empty) {
  rosbag::View all, left;
  for (const auto& bag : bags) {
    all.addQuery(*bag);
    left.addQuery(*bag, rosbag::TopicQuery(left_topic));
  }
  TimeWindow w;
  w.begin = all.getBeginTime();
  const double length = (all.getEndTime() - w.begin).toSec();
  if (start >= 0) w.from = w.begin + ros::Duration(start);
  if (end >= 0) w.to = w.begin + ros::Duration(end);
  rosbag::View count;
  for (const auto& bag : bags) {
    // View ends are inclusive; the window is [from, to).
    count.addQuery(*bag, rosbag::TopicQuery(left_topic), w.from,
                   w.to == ros::TIME_MAX ? w.to : w.to - ros::Duration(0, 1));
  }
  w.sets = static_cast<int>(count.size());
  if (w.sets > 0 || allow_empty) return w;
  const std::string window = "[" + (start >= 0 ? seconds(start) : std::string("start")) + ", " +
                             (end >= 0 ? seconds(end) : std::string("end")) + ")";
  if (start >= 0 && start >= length) {
    throw std::runtime_error("--start " + seconds(start) + " s is past the end of the recording (" +
                             seconds(length) + " s long): no image set to process");
  }
  throw std::runtime_error("no image set in the time window " + window + " s: the recording is " +
                           seconds(length) + " s long and its left images on " + left_topic +
                           " lie in [" + seconds((left.getBeginTime() - w.begin).toSec()) + ", " +
                           seconds((left.getEndTime() - w.begin).toSec()) + "] s");
}

}  // namespace lidar_stereo_fusion
