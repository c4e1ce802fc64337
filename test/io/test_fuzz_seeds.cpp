// Writes the seed corpora of the file-reader fuzz targets (fuzz/, scripts/run_fuzz.sh) into
// <build>/fuzz_seeds/<target>/: valid files of every reader, from the same synthetic values the
// other tests use, plus the inputs that once crashed or misled (issue 9). Each seed is read back
// here, so a seed the reader rejects for the wrong reason fails this test.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/io/calibration_autoware.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/params_yaml.h"
#include "lidar_stereo_fusion/io/pcd.h"

namespace lidar_stereo_fusion {
namespace {

namespace fs = std::filesystem;

fs::path seedDir(const std::string& target) {
  const fs::path dir = fs::path(LSF_BINARY_DIR) / "fuzz_seeds" / target;
  fs::create_directories(dir);
  return dir;
}

void writeSeed(const std::string& target, const std::string& name, const std::string& bytes) {
  std::ofstream(seedDir(target) / name, std::ios::binary) << bytes;
}

std::string readAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

LidarCloud smallSweep() {
  LidarCloud cloud;
  for (int laser = 0; laser < 4; ++laser) {
    for (int k = 0; k < 16; ++k) {
      const double azimuth = (0.5 + 22.5 * k) * M_PI / 180.0, elevation = -2.0 * laser * M_PI / 180;
      LidarPoint p;
      p.x = static_cast<float>(10 * std::cos(elevation) * std::cos(azimuth));
      p.y = static_cast<float>(10 * std::cos(elevation) * std::sin(azimuth));
      p.z = static_cast<float>(10 * std::sin(elevation));
      p.intensity = 0.25f * laser;
      cloud.push_back(p);
    }
  }
  return cloud;
}

const char kCamToCam[] =
    "calib_time: 09-Jan-2012 13:57:47\nR_rect_00: 1 0 0 0 1 0 0 0 1\n"
    "P_rect_02: 60 0 40 3 0 60 30 0 0 0 1 0\nP_rect_03: 60 0 40 -27 0 60 30 0 0 0 1 0\n"
    "S_rect_02: 80 60\n";
const char kVeloToCam[] = "calib_time: 15-Mar-2012 11:37:16\nR: 0 -1 0 0 0 -1 1 0 0\nT: 0 0 0\n";

TEST(FuzzSeeds, KittiCalibrationAndBin) {
  // fuzz_kitti_calib: first byte even = calib_cam_to_cam.txt, odd = calib_velo_to_cam.txt.
  writeSeed("kitti_calib", "cam_to_cam", std::string("\x00", 1) + kCamToCam);
  writeSeed("kitti_calib", "velo_to_cam", std::string("\x01", 1) + kVeloToCam);
  writeSeed("kitti_calib", "size_wraps",
            std::string("\x00", 1) +
                "R_rect_00: 1 0 0 0 1 0 0 0 1\n"
                "P_rect_02: 60 0 40 3 0 60 30 0 0 0 1 0\n"
                "P_rect_03: 60 0 40 -27 0 60 30 0 0 0 1 0\n"
                "S_rect_02: 4294968538 375\n");
  const fs::path dir = fs::temp_directory_path() / ("lsf_seed_calib_" + std::to_string(getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "calib_cam_to_cam.txt") << kCamToCam;
  std::ofstream(dir / "calib_velo_to_cam.txt") << kVeloToCam;
  EXPECT_NEAR(kitti::readCalibration(dir.string()).camera.baseline, 0.5, 1e-12);
  fs::remove_all(dir);

  const fs::path bin = seedDir("kitti_bin") / "sweep_64_points";
  kitti::writeVelodyneBin(bin.string(), smallSweep());
  EXPECT_EQ(kitti::readVelodyneBin(bin.string()).size(), 64u);
  writeSeed("kitti_bin", "not_multiple_of_16", "seventeen bytes!!");
}

TEST(FuzzSeeds, AutowareCalibration) {
  const auto matrix = [](const std::string& key, int rows, int cols, const std::string& data) {
    return key + ": !!opencv-matrix\n   rows: " + std::to_string(rows) +
           "\n   cols: " + std::to_string(cols) + "\n   dt: d\n   data: [ " + data + " ]\n";
  };
  const std::string text =
      "%YAML:1.0\n---\n" +
      matrix("CameraExtrinsicMat", 4, 4, "0, 0, 1, 2, -1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 0, 1") +
      matrix("CameraMat", 3, 3, "1000, 0, 640, 0, 900, 360, 0, 0, 1") +
      matrix("DistCoeff", 1, 5, "0.1, -0.05, 0.001, 0.002, 0.01") + "ImageSize: [ 1280, 720 ]\n" +
      "ReprojectionError: 0.5\nDistModel: plumb_bob\n" +
      matrix("CalibData", 2, 5, "640, 360, 12, 0, 0, 700, 400, 10, -1, -0.5");
  writeSeed("autoware_calib", "synthetic", text);
  // Found by fuzz_autoware_calib: OpenCV allocated rows x cols before reading the data (86 GB).
  const std::string huge =
      "%YAML:1.0\n---\n" + matrix("CameraExtrinsicMat", 2000000000, 40, "1, 2, 3");
  writeSeed("autoware_calib", "huge_matrix", huge);
  writeSeed("autoware_calib", "no_rows",
            "%YAML:1.0\n---\nDistCoeff: !!opencv-matrix\n   rows:`1\n   cols: 5\n   dt: d\n"
            "   data: [ 0.1, -0.05, 0.001, 0.002, 0.01 ]\n");
  try {
    readAutowareCalibration((seedDir("autoware_calib") / "huge_matrix").string());
    ADD_FAILURE() << "a 2000000000x40 matrix with 3 values was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("declares 2000000000x40 but has 3 values"),
              std::string::npos)
        << e.what();
  }
  const auto calib = readAutowareCalibration((seedDir("autoware_calib") / "synthetic").string());
  EXPECT_EQ(calib.image_size, cv::Size(1280, 720));
  EXPECT_EQ(calib.calib_data.size(), 2u);
}

TEST(FuzzSeeds, ParamsYamlAndPcd) {
  const fs::path yaml = seedDir("params_yaml") / "every_field";
  saveParamsYaml(yaml.string(), FusionParams());
  FusionParams p;
  loadParamsYaml(yaml.string(), p);
  writeSeed("params_yaml", "partial", "method: pms\npatchmatch: {window_radius: 8, seed: \"7\"}\n");
  writeSeed("params_yaml", "num_threads_too_many", "patchmatch:\n  num_threads: 100000\n");
  writeSeed("params_yaml", "seed_beyond_int", "patchmatch:\n  seed: 3000000000\n");
  writeSeed("params_yaml", "dash_after_document_end", "...\n-");  // hung OpenCV's parser (CI)
  writeSeed("params_yaml", "shipped", readAll(fs::path(LSF_SOURCE_DIR) / "config" / "fusion.yaml"));

  for (const bool binary : {false, true}) {
    const fs::path pcdPath = seedDir("pcd") / (binary ? "binary.pcd" : "ascii.pcd");
    pcd::writePcd(pcdPath.string(), smallSweep(), binary);
    EXPECT_EQ(pcd::readPcd(pcdPath.string()).size(), 64u) << pcdPath;
  }
  const fs::path compressed = seedDir("pcd") / "binary_compressed.pcd";  // LZF, through PCL
  pcd::writePcd(compressed.string(), smallSweep(), pcd::DataKind::kBinaryCompressed);
  EXPECT_EQ(pcd::readPcd(compressed.string()).size(), 64u) << compressed;
}

}  // namespace
}  // namespace lidar_stereo_fusion
