// The files written from the parameter tables (core/param_table.h, ros/node_params.h): YAML with
// every row documented, the Markdown tables of doc/parameters.md and cfg/Fusion.cfg. The
// `lsf_params` tool writes them into the source tree; test_tools fails when a committed file
// differs from what these functions make of the tables.
#pragma once

#include <string>
#include <vector>

#include "lidar_stereo_fusion/io/param_table.h"

namespace lidar_stereo_fusion {

/// YAML (rosparam and loadParamsYaml alike) with the rows' values: `header` as comments, a comment
/// line per group, and each row's documentation (unit, range) on the line above its key. Names
/// "a/b" become key b of a section a.
std::string renderParamsYaml(const std::vector<ParamInfo>& rows, const std::string& header);

/// A Markdown table of the rows: group, parameter, default with unit, allowed values, meaning,
/// and with `live_column` whether dynamic_reconfigure changes it while the node runs.
std::string renderParamsMarkdown(const std::vector<ParamInfo>& rows, bool live_column);

/// cfg/Fusion.cfg (dynamic_reconfigure's generator script) with every row whose `live` is set,
/// each in its group, without slider ranges (the node checks requests with the table's ranges
/// and refuses out-of-range values visibly; the server would clamp them silently).
std::string renderFusionCfg(const std::vector<ParamInfo>& rows);

/// `text` with the part between the lines `begin` and `end` (both kept) replaced by `block`.
/// Throws std::runtime_error when a marker is missing.
std::string replaceBetween(const std::string& text, const std::string& begin,
                           const std::string& end, const std::string& block);

}  // namespace lidar_stereo_fusion
