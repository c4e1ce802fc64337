// FusionParams <-> ROS parameters and dynamic_reconfigure. No defaults live here: they come from
// the core structs, and this layer only fills them.
//
// Names: the ROS parameter `group/field` (config/fusion.yaml, the io/params_yaml.h layout, in the
// nodelet's private namespace) is the dynamic_reconfigure parameter `group_field` (cfg/Fusion.cfg);
// `method` has no group.
#pragma once

#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "lidar_stereo_fusion/FusionConfig.h"
#include "lidar_stereo_fusion/core/pipeline.h"

namespace lidar_stereo_fusion {
namespace ros_params {

/// One parameter of FusionParams, for listing and diagnostics.
struct ParamInfo {
  std::string ros_name;          ///< e.g. "patchmatch/window_radius"
  std::string reconfigure_name;  ///< e.g. "patchmatch_window_radius"
  std::string type;              ///< "double", "int", "bool" or "string"
};

/// Every parameter of FusionParams, in declaration order.
std::vector<ParamInfo> listParams();

/// Reads the parameters present under `pnh` into a copy of `base`. A parameter with a wrong type
/// or an impossible value (e.g. an unknown method name) is skipped, keeping its value from `base`,
/// and described in `errors` (naming the parameter); so are unknown keys under the groups (typos).
/// The combination is not validated here.
FusionParams readParams(const ros::NodeHandle& pnh, const FusionParams& base,
                        std::vector<std::string>* errors);

/// Writes every parameter to the parameter server under `pnh` (the effective configuration).
void writeParams(const ros::NodeHandle& pnh, const FusionParams& params);

/// FusionParams as a dynamic_reconfigure config.
FusionConfig toConfig(const FusionParams& params);

/// The dynamic_reconfigure config as FusionParams (not validated). Throws std::invalid_argument
/// naming the parameter for values that cannot be represented (unknown method, negative seed).
FusionParams fromConfig(const FusionConfig& config);

/// "group/field: old -> new" for every parameter that differs, comma separated.
std::string describeChanges(const FusionParams& from, const FusionParams& to);

}  // namespace ros_params
}  // namespace lidar_stereo_fusion
