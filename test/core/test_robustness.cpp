// Regression tests for the crashes and silent failures of issue 9 that need no ROS: every input
// here once crashed a process or was accepted without a word.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <unistd.h>

#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/io/params_yaml.h"

namespace lidar_stereo_fusion {
namespace {

namespace fs = std::filesystem;

std::string yamlLoadError(const std::string& text) {
  const fs::path path =
      fs::temp_directory_path() / ("lsf_robust_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(path) << text;
  FusionParams p;
  std::string error;
  try {
    loadParamsYaml(path.string(), p);
  } catch (const std::exception& e) {
    error = e.what();
  }
  fs::remove(path);
  return error;
}

// Issue 9, crash 3: num_threads 100000 from a --params YAML reached libgomp (SIGSEGV).
TEST(Robustness, HugeThreadCountIsRejectedByValidateAndTheYamlLoader) {
  PatchMatchParams m;
  m.num_threads = 100000;
  try {
    m.validate();
    ADD_FAILURE() << "num_threads 100000 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("num_threads"), std::string::npos) << e.what();
  }
  m.num_threads = 256;
  EXPECT_NO_THROW(m.validate());
  m.num_threads = 0;
  EXPECT_NO_THROW(m.validate());

  const std::string error = yamlLoadError("patchmatch:\n  num_threads: 100000\n");
  EXPECT_NE(error.find("'num_threads'"), std::string::npos) << error;
  EXPECT_NE(error.find("[0, 256]"), std::string::npos) << error;
  EXPECT_EQ(yamlLoadError("patchmatch:\n  num_threads: 2\n"), "");
}

}  // namespace
}  // namespace lidar_stereo_fusion
