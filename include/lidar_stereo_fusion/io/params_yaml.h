// Loading FusionParams from YAML (OpenCV FileStorage). The same layout is used by
// config/*.yaml for the ROS nodes:
//   method: fused_bi            # fused_bi | fused_bf | pms | lidar_bi | lidar_bf
//   projection: {min_depth: 0.5, max_depth: 200.0}
//   bi: {max_gap_px: 12, ...}
//   bf: {radius: 6, ...}
//   patchmatch: {window_radius: 5, alpha: 0.1, ...}
// Every key is optional; unknown keys are an error (typos must not pass silently). Every line
// but blank lines, comments, a "%YAML" directive and document markers is "name: value" or a
// section "name:", indented by spaces and never less than the first name (OpenCV 4.6's parser
// never returns on some documents outside that form: they are refused by line first).
#pragma once

#include <string>

#include <opencv2/core/persistence.hpp>

#include "lidar_stereo_fusion/core/pipeline.h"

namespace lidar_stereo_fusion {

/// Overrides the fields of `params` named in the YAML file and validates the result.
/// Throws std::runtime_error naming the file and the offending key or value.
void loadParamsYaml(const std::string& path, FusionParams& params);

/// Opens a YAML file (rosparam style, no "%YAML" directive needed) for reading with OpenCV's
/// FileStorage, after the checks of loadParamsYaml (text, document markers). Throws
/// std::runtime_error naming the file.
cv::FileStorage openYaml(const std::string& path);

/// Writes every field (the effective configuration) as YAML to `path`.
void saveParamsYaml(const std::string& path, const FusionParams& params);

}  // namespace lidar_stereo_fusion
