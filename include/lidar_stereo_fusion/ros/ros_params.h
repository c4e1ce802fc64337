// The parameter tables (core/param_table.h, ros/node_params.h) <-> ROS parameters and
// dynamic_reconfigure. No defaults live here: they come from the structs, and this layer only
// fills them; every value read is checked against its row's range as it is read.
//
// Names: one per parameter (core/param_table.h): the ROS parameter ~window_radius in the nodelet's
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
#include "lidar_stereo_fusion/ros/node_params.h"

namespace lidar_stereo_fusion {
namespace ros_params {

/// Every parameter of FusionParams, in table order (core/param_table.h).
std::vector<ParamInfo> listParams();

/// Every node parameter, in table order (ros/node_params.h).
std::vector<ParamInfo> listNodeParams();

/// Reads the parameters present under `pnh` into a copy of `base`. A parameter with a wrong type,
/// a value outside its row's range or an impossible name (e.g. an unknown method) is skipped,
/// keeping its value from `base`, and described in `errors` (naming the parameter, with the
/// sentence validate() would say); so are deprecated names (read, then deleted) and other keys
/// under the old groups (typos). The checks between parameters are the caller's validate().
FusionParams readParams(const ros::NodeHandle& pnh, const FusionParams& base,
                        std::vector<std::string>* errors);

/// The node parameters under `pnh`, read and checked like readParams(); when the checks between
/// them fail, every node parameter keeps its default (said in `errors`).
NodeParams readNodeParams(const ros::NodeHandle& pnh, std::vector<std::string>* errors);

/// Writes every parameter to the parameter server under `pnh` (the effective configuration).
void writeParams(const ros::NodeHandle& pnh, const FusionParams& params);

/// FusionParams and the node's live parameters as a dynamic_reconfigure config.
FusionConfig toConfig(const FusionParams& params, const NodeParams& node = NodeParams());

/// The dynamic_reconfigure config as FusionParams, and into `node` (when given) its live rows
/// (not validated). Throws std::invalid_argument naming the parameter for values that cannot be
/// represented (unknown method, negative seed).
FusionParams fromConfig(const FusionConfig& config, NodeParams* node = nullptr);

/// "name: old -> new" for every parameter that differs, comma separated.
std::string describeChanges(const FusionParams& from, const FusionParams& to);
std::string describeChanges(const NodeParams& from, const NodeParams& to);

/// "name = asked (in force: value)" for every parameter a dynamic_reconfigure request changes, from
/// the request's raw values (so a value no field can hold, e.g. method "bogus", is shown as asked);
/// "no change" when it changes nothing.
std::string describeRequest(const FusionParams& current, const NodeParams& node,
                            const FusionConfig& requested);

}  // namespace ros_params
}  // namespace lidar_stereo_fusion
