// The node's parameters: their checks and their YAML file (the table is ros/node_params.h).
#include "lidar_stereo_fusion/ros/node_params.h"

#include <stdexcept>

#include "lidar_stereo_fusion/io/param_table.h"
#include "lidar_stereo_fusion/io/param_yaml_reader.h"
#include "lidar_stereo_fusion/io/params_yaml.h"

namespace lidar_stereo_fusion {

void NodeParams::validate() const {
  requireRanges("NodeParams", *this);
  if (diag_min_rate > diag_max_rate) {
    throw std::invalid_argument(
        "NodeParams: diagnostics/min_rate must be <= diagnostics/max_rate (" +
        formatParamDouble(diag_max_rate) + ") Hz, got " + formatParamDouble(diag_min_rate));
  }
}

std::vector<ParamInfo> nodeParamTable() {
  std::vector<ParamInfo> out;
  const NodeParams defaults;
  visitParams(defaults, ParamLister{out});
  return out;
}

NodeParams readNodeParamsYaml(const std::string& path) {
  cv::FileStorage file = openYaml(path);
  const cv::FileNode root = file.root();
  NodeParams p;
  if (root.empty() || root.isNone()) return p;
  if (!root.isMap()) throw std::runtime_error("params YAML " + path + ": top level is not a map");
  rejectUnknownParamKeys(root, path, nodeParamTable(), /*group_sections=*/false);
  visitParams(p, YamlParamReader(root, path, /*group_sections=*/false));
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("params YAML " + path + ": invalid value: " + e.what());
  }
  return p;
}

}  // namespace lidar_stereo_fusion
