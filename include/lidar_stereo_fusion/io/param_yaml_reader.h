// Reading the rows of a parameter table (core/param_table.h, ros/node_params.h) from a YAML file
// opened with openYaml(): one reader for the algorithm's and the node's parameters, with errors
// naming the file and the key.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core/persistence.hpp>

#include "lidar_stereo_fusion/core/param_spec.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/io/param_table.h"

namespace lidar_stereo_fusion {

/// Table visitor: sets each field whose name is in the YAML map. A key is looked up at the top
/// level, then (the deprecated layout of the algorithm's parameters, `group_sections`) in its
/// group's section; a name "a/b" is key b of section a. Throws std::runtime_error("params YAML
/// <path>: key '<name>' ...") on a wrong type, a NaN or a word outside the row's choices. Ranges
/// are the caller's validate().
class YamlParamReader {
 public:
  YamlParamReader(const cv::FileNode& root, std::string path, bool group_sections = true)
      : root_(root), path_(std::move(path)), group_sections_(group_sections) {}

  template <class T>
  void operator()(const ParamSpec& spec, T& value) const {
    const cv::FileNode node = find(spec);
    if (!node.empty()) read(node, spec, value);
  }

 private:
  cv::FileNode find(const ParamSpec& spec) const;
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;
  void read(const cv::FileNode& node, const ParamSpec& spec, Method& value) const;
  void read(const cv::FileNode& node, const ParamSpec& spec, double& value) const;
  void read(const cv::FileNode& node, const ParamSpec& spec, int& value) const;
  void read(const cv::FileNode& node, const ParamSpec& spec, bool& value) const;
  void read(const cv::FileNode& node, const ParamSpec& spec, uint64_t& value) const;
  void read(const cv::FileNode& node, const ParamSpec& spec, std::string& value) const;

  cv::FileNode root_;
  std::string path_;
  bool group_sections_;
};

/// Throws std::runtime_error naming the file and the key for a top-level key that is no row of
/// `table` nor a section holding only rows of its group (typos must not pass silently). Without
/// `group_sections` the only sections are those of names "a/b".
void rejectUnknownParamKeys(const cv::FileNode& root, const std::string& path,
                            const std::vector<ParamInfo>& table, bool group_sections = true);

}  // namespace lidar_stereo_fusion
