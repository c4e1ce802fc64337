// PCD files and PCL's tools on real data (issue 26): the VLS-128 sweep converted to
// binary_compressed by pcl_convert_pcd_ascii_binary reads back exactly; kitti_runner --save-pcd
// writes, for every frame, a file PCL's converter reads that holds exactly the finite points of
// that frame's depth.
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "data/data_guard.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/params_yaml.h"
#include "lidar_stereo_fusion/io/pcd.h"

namespace lidar_stereo_fusion {
namespace {

namespace fs = std::filesystem;

const char* const kVls128 = "vls128/1585897255376374245.pcd";
const char* const kDrive = "kitti_raw/2011_09_26/2011_09_26_drive_0009_sync";

/// Exit status of a shell command (its output goes to `log`).
int run(const std::string& command, const fs::path& log) {
  const int raw = std::system((command + " > " + log.string() + " 2>&1").c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

std::string readAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path scratch(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("lsf_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(PcdData, Vls128ConvertedByPclToBinaryCompressedReadsBackExactly) {
  LSF_REQUIRE_DATA(kVls128);
  const fs::path dir = scratch("vls128_pcd");
  const fs::path compressed = dir / "vls128_compressed.pcd";
  ASSERT_EQ(run("pcl_convert_pcd_ascii_binary " + test::dataPath(kVls128) + " " +
                    compressed.string() + " 2",
                dir / "convert.log"),
            0)
      << readAll(dir / "convert.log");
  pcd::Header header;
  const LidarCloud original = pcd::readPcd(test::dataPath(kVls128));
  const LidarCloud back = pcd::readPcd(compressed.string(), &header);
  EXPECT_EQ(header.data, "binary_compressed");
  ASSERT_EQ(back.size(), 208680u);
  ASSERT_EQ(back.size(), original.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < back.size(); ++i) {
    if (back[i].x != original[i].x || back[i].y != original[i].y || back[i].z != original[i].z) {
      ++differ;
    }
  }
  EXPECT_EQ(differ, 0u);

  // The same file cut short, and with its LZF stream damaged: this package's messages.
  const std::string bytes = readAll(compressed);
  const fs::path cut = dir / "cut.pcd";
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  std::string damaged = bytes;
  for (std::size_t k = bytes.size() / 3; k < bytes.size(); k += 101) damaged[k] = '\x7f';
  const fs::path bad = dir / "damaged.pcd";
  std::ofstream(bad, std::ios::binary) << damaged;
  for (const auto& [path, message] :
       {std::pair<fs::path, std::string>{cut, "binary_compressed is truncated"},
        {bad, "the LZF data is corrupt"}}) {
    try {
      pcd::readPcd(path.string());
      ADD_FAILURE() << "no error for " << path;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
  fs::remove_all(dir);
}

std::string runnerPath() {
  const fs::path build(LSF_BINARY_DIR);
  for (const fs::path& candidate :
       {build / "kitti_runner",
        build / ".." / ".." / "devel" / "lib" / "lidar_stereo_fusion" / "kitti_runner"}) {
    if (fs::is_regular_file(candidate)) return candidate.string();
  }
  return "";
}

/// x y z of an ascii PCD (as pcl_convert_pcd_ascii_binary writes it: x y z first).
std::vector<cv::Vec3f> asciiPoints(const fs::path& path, std::string* fields) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line) && line.rfind("DATA", 0) != 0) {
    if (line.rfind("FIELDS", 0) == 0) *fields = line;
  }
  EXPECT_EQ(line, "DATA ascii") << path;
  std::vector<cv::Vec3f> points;
  float x, y, z;
  std::string rest;
  while (in >> x >> y >> z) {
    std::getline(in, rest);
    points.emplace_back(x, y, z);
  }
  return points;
}

TEST(PcdData, KittiRunnerSavePcdHoldsExactlyTheFinitePointsOfEachFramesDepth) {
  LSF_REQUIRE_DATA(kDrive);
  const std::string runner = runnerPath();
  if (runner.empty()) GTEST_SKIP() << "kitti_runner is not built next to " << LSF_BINARY_DIR;
  const fs::path out = scratch("save_pcd");
  const std::string params = std::string(LSF_SOURCE_DIR) + "/config/live.yaml";
  const std::string drive = test::dataPath(kDrive);
  ASSERT_EQ(run(runner + " --kitti-raw " + drive + " --out " + out.string() + " --params " +
                    params + " --frames 2 --save-pcd",
                out / "runner.log"),
            0)
      << readAll(out / "runner.log");

  FusionParams fusion_params;
  loadParamsYaml(params, fusion_params);
  FusionPipeline pipeline(fusion_params);
  const kitti::Calibration calib = kitti::readCalibration(kitti::calibrationDirOf(drive));
  std::vector<kitti::Frame> frames = kitti::listFrames(drive);
  frames.resize(2);
  for (const kitti::Frame& frame : frames) {
    SCOPED_TRACE(frame.name);
    const fs::path file = out / (frame.name + ".pcd");
    ASSERT_TRUE(fs::exists(file));
    const std::string head = readAll(file).substr(0, 400);
    EXPECT_NE(head.find("FIELDS x y z rgb\n"), std::string::npos) << head;
    EXPECT_NE(head.find("DATA binary_compressed\n"), std::string::npos) << head;
    const fs::path ascii = out / (frame.name + "_ascii.pcd");
    ASSERT_EQ(run("pcl_convert_pcd_ascii_binary " + file.string() + " " + ascii.string() + " 0 9",
                  out / "convert.log"),
              0)
        << readAll(out / "convert.log");
    std::string fields;
    const std::vector<cv::Vec3f> points = asciiPoints(ascii, &fields);
    EXPECT_EQ(fields, "FIELDS x y z rgb");

    const kitti::FrameData data = kitti::loadFrame(frame, calib.camera);
    const cv::Mat1f depth =
        pipeline.process({data.left, data.right, data.cloud, calib.T_cam_velo, calib.camera}).depth;
    std::size_t next = 0, far = 0, with_depth = 0;
    for (int v = 0; v < depth.rows; ++v) {
      for (int u = 0; u < depth.cols; ++u) {
        const float z = depth(v, u);
        if (!(std::isfinite(z) && z > 0.f)) continue;
        ++with_depth;
        if (next < points.size() && !(std::abs(points[next][2] - z) <= 1e-3f)) ++far;
        ++next;
      }
    }
    EXPECT_GT(with_depth, 100000u);
    EXPECT_EQ(points.size(), with_depth) << "the file holds another number of points";
    EXPECT_EQ(far, 0u) << "points whose z is not the depth within 1 mm";
  }
  fs::remove_all(out);
}

}  // namespace
}  // namespace lidar_stereo_fusion
