// The files generated from the parameter tables, as they should read: cfg/Fusion.cfg,
// config/fusion.yaml, config/fusion_node.yaml and the tables in doc/parameters.md. The
// `lsf_params` tool writes (or checks) them; test_tools compares them with the committed files.
#pragma once

#include <string>
#include <vector>

namespace lidar_stereo_fusion {

struct GeneratedFile {
  std::string path;      ///< relative to the package's source folder
  std::string contents;  ///< what the tables make of it
};

/// Every generated file. doc/parameters.md keeps its prose: only the parts between its markers
/// are generated (so it is read from `source_dir`). Throws std::runtime_error when it cannot be
/// read or lost its markers.
std::vector<GeneratedFile> generatedParamFiles(const std::string& source_dir);

}  // namespace lidar_stereo_fusion
