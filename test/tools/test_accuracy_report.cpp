// accuracy_report's command line: an option that only a protocol left out would read is refused
// with a message naming it (exit 2, before any data is read), never ignored; a --save-dir that
// cannot be made stops the run before any protocol (exit 1).
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "tools/tool_runner.h"

namespace lsf = lidar_stereo_fusion;

namespace {

/// Runs accuracy_report with `args` in a scratch folder (its output captured there).
lsf::test::RunResult accuracyReport(const std::string& args) {
  namespace fs = std::filesystem;
  const std::string path = lsf::test::toolPath("accuracy_report");
  EXPECT_FALSE(path.empty()) << "accuracy_report is not built next to " << LSF_BINARY_DIR;
  const fs::path scratch =
      fs::temp_directory_path() / ("lsf_accuracy_report_" + std::to_string(::getpid()));
  fs::create_directories(scratch);
  const lsf::test::RunResult r =
      lsf::test::runCommand(path + " --data /nonexistent " + args, scratch);
  fs::remove_all(scratch);
  return r;
}

TEST(AccuracyReportOptions, AnOptionForAProtocolThatDoesNotRunIsRefused) {
  const struct {
    const char* args;
    const char* named;
  } cases[] = {
      {"--protocols middlebury --sweep-order shuffled", "--sweep-order applies to the kitti"},
      {"--protocols synthetic --stereo-check 3", "--stereo-check applies to the dense"},
      {"--protocols kitti --keep-unverified", "--keep-unverified applies to the dense"},
      {"--layouts ring32 --reference majority", "--reference applies to the dense"},
      {"--protocols dense --frames 2", "--frames applies to the kitti"},
  };
  for (const auto& c : cases) {
    const lsf::test::RunResult r = accuracyReport(c.args);
    EXPECT_EQ(r.status, 2) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.named), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(r.out, "") << c.args;
  }
}

TEST(AccuracyReportOptions, AnUnknownSweepOrderIsNamedWithTheValidOnes) {
  const lsf::test::RunResult r = accuracyReport("--protocols dense --sweep-order sorted");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("'sorted'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("image-rows-cropped"), std::string::npos) << r.err;
}

TEST(AccuracyReportOptions, ASaveDirThatCannotBeMadeStopsBeforeAnyProtocol) {
  namespace fs = std::filesystem;
  const fs::path file =
      fs::temp_directory_path() / ("lsf_accuracy_report_file_" + std::to_string(::getpid()));
  std::ofstream(file) << "x";
  const std::string dir = (file / "sub").string();
  const lsf::test::RunResult r = accuracyReport("--protocols synthetic --save-dir " + dir);
  fs::remove(file);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("--save-dir: cannot create the folder " + dir), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
}

}  // namespace
