// The files generated from the parameter tables (cfg/Fusion.cfg, config/fusion.yaml,
// config/fusion_node.yaml, doc/parameters.md's tables) are what the tables make, and lsf_params
// --check / --write find and rewrite a stale one. ROS-free: runs in the plain CMake build too.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/io/text_file.h"
#include "lidar_stereo_fusion/ros/param_files.h"
#include "tools/tool_runner.h"

namespace lsf = lidar_stereo_fusion;
namespace fs = std::filesystem;

namespace {

/// A scratch source folder holding the generated files as the tables make them.
class GeneratedCopy {
 public:
  GeneratedCopy() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    root_ = fs::temp_directory_path() /
            ("lsf_params_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    for (const auto& file : lsf::generatedParamFiles(LSF_SOURCE_DIR)) {
      fs::create_directories((root_ / file.path).parent_path());
      std::ofstream(root_ / file.path) << file.contents;
    }
  }
  ~GeneratedCopy() { fs::remove_all(root_); }
  const fs::path& root() const { return root_; }

 private:
  fs::path root_;
};

std::string lsfParams() { return lsf::test::toolPath("lsf_params"); }

}  // namespace

TEST(RosParams, GeneratedFilesAreWhatTheTablesMake) {
  // cfg/Fusion.cfg, config/fusion.yaml, config/fusion_node.yaml and doc/parameters.md's tables.
  for (const auto& file : lsf::generatedParamFiles(LSF_SOURCE_DIR)) {
    const std::string committed =
        lsf::readTextFile(std::string(LSF_SOURCE_DIR) + "/" + file.path, "generated file");
    EXPECT_TRUE(committed == file.contents)
        << file.path << " differs from the parameter tables (core/param_table.h, "
        << "ros/node_params.h): run `rosrun lidar_stereo_fusion lsf_params --write`";
  }
}

TEST(LsfParams, CheckNamesAStaleFileAndWriteRegeneratesIt) {
  ASSERT_FALSE(lsfParams().empty()) << "lsf_params is not built next to " << LSF_BINARY_DIR;
  GeneratedCopy copy;
  const std::string dir = copy.root().string();
  lsf::test::RunResult r = lsf::test::runCommand(lsfParams() + " --check " + dir, copy.root());
  EXPECT_EQ(r.status, 0) << r.err;

  std::ofstream(copy.root() / "config/fusion.yaml", std::ios::app) << "window_radius: 3\n";
  r = lsf::test::runCommand(lsfParams() + " --check " + dir, copy.root());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("config/fusion.yaml differs from the parameter tables"), std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("cfg/Fusion.cfg"), std::string::npos) << r.err;

  r = lsf::test::runCommand(lsfParams() + " --write " + dir, copy.root());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("wrote config/fusion.yaml"), std::string::npos) << r.out;
  r = lsf::test::runCommand(lsfParams() + " --check " + dir, copy.root());
  EXPECT_EQ(r.status, 0) << r.err;
}

TEST(LsfParams, CheckOfTheSourceTreePassesAndABadCommandLineExitsWith2) {
  ASSERT_FALSE(lsfParams().empty()) << "lsf_params is not built next to " << LSF_BINARY_DIR;
  GeneratedCopy copy;  // a folder of its own for the captured output
  const fs::path& scratch = copy.root();
  lsf::test::RunResult r =
      lsf::test::runCommand(lsfParams() + " --check " + LSF_SOURCE_DIR, scratch);
  EXPECT_EQ(r.status, 0) << r.err;
  r = lsf::test::runCommand(lsfParams() + " --bogus", scratch);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("usage: lsf_params"), std::string::npos) << r.err;
}
