// Every ROS-free tool has the one main of io/cli.h: --help prints its usage and exits 0 without
// doing anything; an unknown argument is named, with the usage, and exits 2.
#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "tools/tool_runner.h"

namespace lsf = lidar_stereo_fusion;
namespace fs = std::filesystem;

namespace {

class ToolMain : public ::testing::TestWithParam<const char*> {
 protected:
  void SetUp() override {
    scratch_ = fs::temp_directory_path() /
               ("lsf_tool_main_" + std::string(GetParam()) + "_" + std::to_string(::getpid()));
    fs::create_directories(scratch_);
    path_ = lsf::test::toolPath(GetParam());
    ASSERT_FALSE(path_.empty()) << GetParam() << " is not built next to " << LSF_BINARY_DIR;
  }
  void TearDown() override { fs::remove_all(scratch_); }
  /// Runs the tool in the scratch folder, so that anything it writes lands there.
  lsf::test::RunResult run(const std::string& args) const {
    return lsf::test::runCommand("cd " + scratch_.string() + " && " + path_ + " " + args, scratch_);
  }
  /// Entries of the scratch folder besides the captured output.
  int written() const {
    int n = 0;
    for (const auto& entry : fs::directory_iterator(scratch_)) {
      const std::string name = entry.path().filename().string();
      n += name != "stdout.txt" && name != "stderr.txt";
    }
    return n;
  }
  fs::path scratch_;
  std::string path_;
};

}  // namespace

TEST_P(ToolMain, HelpPrintsTheUsageAndExits0) {
  const lsf::test::RunResult r = run("--help");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find(GetParam()), std::string::npos) << "the usage names the tool:\n" << r.out;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(run("-h").out, r.out);
  EXPECT_EQ(written(), 0) << "--help wrote something";
}

TEST_P(ToolMain, AnUnknownArgumentIsNamedWithTheUsageAndExits2) {
  const lsf::test::RunResult r = run("--no-such-option");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(std::string(GetParam()) + ": "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--no-such-option"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("sage"), std::string::npos) << "no usage after the message:\n" << r.err;
  EXPECT_EQ(r.out, "");
}

INSTANTIATE_TEST_SUITE_P(Tools, ToolMain,
                         ::testing::Values("accuracy_report", "fusion_benchmark", "kitti_runner",
                                           "lsf_demo", "lsf_params", "moving_rig_report"));
