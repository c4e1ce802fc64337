// FusionParams <-> ROS parameters and dynamic_reconfigure. No defaults live here: they come from
// the core structs, and this layer only fills them.
//
// Names: one per parameter (io/param_table.h): the ROS parameter ~window_radius in the nodelet's
// private namespace is the dynamic_reconfigure parameter window_radius and the YAML key
// window_radius. The former spellings ~patchmatch/window_radius and ~patchmatch_window_radius are
// read once as deprecated aliases (with a message) and deleted.
#pragma once

#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "lidar_stereo_fusion/FusionConfig.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/io/param_table.h"

namespace lidar_stereo_fusion {
namespace ros_params {

/// Every parameter of FusionParams, in table order (io/param_table.h).
std::vector<ParamInfo> listParams();

/// Reads the parameters present under `pnh` into a copy of `base`. A parameter with a wrong type
/// or an impossible value (e.g. an unknown method name) is skipped, keeping its value from `base`,
/// and described in `errors` (naming the parameter); so are deprecated names (read, then deleted)
/// and other keys under the old groups (typos).
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

/// "name: old -> new" for every parameter that differs, comma separated.
std::string describeChanges(const FusionParams& from, const FusionParams& to);

/// "name = asked (in force: value)" for every parameter a dynamic_reconfigure request changes, from
/// the request's raw values (so a value no field can hold, e.g. method "bogus", is shown as asked);
/// "no change" when it changes nothing.
std::string describeRequest(const FusionParams& current, const FusionConfig& requested);

}  // namespace ros_params
}  // namespace lidar_stereo_fusion
