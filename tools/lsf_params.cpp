// lsf_params: writes or checks the files generated from the parameter tables
// (core/param_table.h, ros/node_params.h): cfg/Fusion.cfg, config/fusion.yaml,
// config/fusion_node.yaml and the tables of doc/parameters.md.
//
//   rosrun lidar_stereo_fusion lsf_params --check [SOURCE_DIR]   exit 1 naming every stale file
//   rosrun lidar_stereo_fusion lsf_params --write [SOURCE_DIR]   rewrite the stale ones
//   rosrun lidar_stereo_fusion lsf_params --print PATH           one file as generated, to stdout
#include <exception>
#include <fstream>
#include <iostream>
#include <string>

#include "lidar_stereo_fusion/io/cli.h"
#include "lidar_stereo_fusion/io/text_file.h"
#include "lidar_stereo_fusion/ros/param_files.h"

namespace {

constexpr const char* kUsage =
    "usage: lsf_params --check|--write [SOURCE_DIR]\n"
    "       lsf_params --print PATH   (cfg/Fusion.cfg, config/fusion.yaml, ...)\n"
    "SOURCE_DIR defaults to the package's source folder: " LSF_SOURCE_DIR "\n";

/// The file's text, or "" when it is missing or unreadable.
std::string current(const std::string& path) {
  try {
    return lidar_stereo_fusion::readTextFile(path, "generated file");
  } catch (const std::exception&) {
    return {};
  }
}

int print(const std::string& which) {
  for (const auto& file : lidar_stereo_fusion::generatedParamFiles(LSF_SOURCE_DIR)) {
    if (file.path != which) continue;
    std::cout << file.contents;
    return 0;
  }
  throw lidar_stereo_fusion::UsageError(which + " is not a generated file");
}

/// --check: names every stale file; --write: rewrites them. 1 when a file is stale (check) or
/// could not be written.
int checkOrWrite(bool write, const std::string& dir) {
  int failed = 0;
  for (const auto& file : lidar_stereo_fusion::generatedParamFiles(dir)) {
    const std::string path = dir + "/" + file.path;
    if (current(path) == file.contents) continue;
    if (!write) {
      std::cerr << "lsf_params: " << file.path << " differs from the parameter tables\n";
      ++failed;
      continue;
    }
    std::ofstream out(path);
    out << file.contents;
    if (out) {
      std::cout << "lsf_params: wrote " << file.path << "\n";
    } else {
      std::cerr << "lsf_params: cannot write " << path << "\n";
      ++failed;
    }
  }
  if (!write && failed > 0) {
    std::cerr << "lsf_params: `rosrun lidar_stereo_fusion lsf_params --write` regenerates them\n";
  }
  return failed > 0 ? 1 : 0;
}

/// The mode and its folder or file from the command line; UsageError when they do not fit.
int run(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode != "--check" && mode != "--write" && mode != "--print") {
    throw lidar_stereo_fusion::UsageError(mode.empty() ? "no mode" : "unknown mode '" + mode + "'");
  }
  if (argc > 3 || (mode == "--print" && argc != 3)) {
    throw lidar_stereo_fusion::UsageError(mode == "--print" ? "--print takes one PATH"
                                                            : mode + " takes at most a folder");
  }
  if (mode == "--print") return print(argv[2]);
  return checkOrWrite(mode == "--write", argc > 2 ? argv[2] : LSF_SOURCE_DIR);
}

}  // namespace

int main(int argc, char** argv) {
  return lidar_stereo_fusion::toolMain("lsf_params", kUsage, argc, argv,
                                       [&] { return run(argc, argv); });
}
