// Regression tests for the crashes and silent failures of issue 9 that need no ROS: every input
// here once crashed a process or was accepted without a word.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/io/kitti.h"
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

// Point 10: a binary file loaded as the defaults (OpenCV stops at the first NUL); a seed of
// 3000000000 was reported as "must be >= 0".
TEST(Robustness, BinaryYamlAndUnquotedBigSeedAreNamedProperly) {
  const std::string binary =
      yamlLoadError(std::string("\x7f"
                                "ELF\x02\x01\x01\0\0\0method: pms\n",
                                21));
  EXPECT_NE(binary.find("not a text file"), std::string::npos) << binary;
  const std::string seed = yamlLoadError("patchmatch:\n  seed: 3000000000\n");
  EXPECT_NE(seed.find("quoted"), std::string::npos) << seed;
  EXPECT_EQ(yamlLoadError("patchmatch:\n  seed: \"3000000000\"\n"), "");
}

TEST(Robustness, YamlLinesThatAreNotNameAndValueAreErrorsBeforeOpenCvParsesThem) {
  // OpenCV 4.6's parser never returns on " d:0\nx.\n-" (found by fuzz_params_yaml in CI: a
  // map's first name indented, then lines that are neither): every line must be "name: value"
  // or a section "name:", indented by spaces, never less than the first name.
  const std::vector<std::pair<std::string, std::vector<std::string>>> refused = {
      {" d:0\nx.\n-", {"line 2", "not 'name: value'"}},
      {"seed: 7\nfoo\n", {"line 2", "not 'name: value'"}},
      {"seed: 7\n- 3\n", {"line 2", "not 'name: value'"}},
      {"\"seed\": 7\n", {"line 1", "not 'name: value'"}},
      {"  seed: 7\nwindow_radius: 5\n", {"line 2", "indented by 0 spaces", "first name's 2"}},
      {"\tseed: 7\n", {"line 1", "a tab in the indentation"}},
  };
  for (const auto& [text, parts] : refused) {
    const std::string error = yamlLoadError(text);
    for (const std::string& part : parts) {
      EXPECT_NE(error.find(part), std::string::npos) << text << " -> " << error;
    }
  }
  // What parameter files hold stays accepted: no space after the colon, a section, comments, the
  // directive, a first name indented like the rest.
  for (const char* text : {"seed:7\n", "patchmatch:\n  seed: 7  # c\n\n# end\n",
                           "%YAML:1.0\n---\nseed: 7\n", "  seed: 7\n  window_radius: 5\n"}) {
    EXPECT_EQ(yamlLoadError(text), "") << text;
  }
}

// Point 5: a right projection in millimetres gives a 1000x baseline.
TEST(Robustness, ImplausibleBaselineNamesTheValueAndTheUnitMistake) {
  EXPECT_EQ(baselinePlausibilityProblem(0.537), "");
  EXPECT_EQ(baselinePlausibilityProblem(0.063), "");
  const std::string mm = baselinePlausibilityProblem(537.15);
  EXPECT_NE(mm.find("537.15"), std::string::npos) << mm;
  EXPECT_NE(mm.find("millimetres"), std::string::npos) << mm;
  EXPECT_NE(mm.find("0.537"), std::string::npos) << mm;
  EXPECT_NE(baselinePlausibilityProblem(0.0005), "");
  EXPECT_NE(baselinePlausibilityProblem(std::nan("")), "");
}

// Issue 25, point 7: an all-NaN sweep (a corrupt .bin) is named as not finite, not as landing
// outside the image; and the count of non-finite points is in the message otherwise.
TEST(Robustness, AnAllNanSweepIsNamedAsNotFinite) {
  FusionInput input;
  input.left = cv::Mat(40, 60, CV_8UC3, cv::Scalar(80, 90, 100));
  input.right = input.left.clone();
  input.camera.fx = input.camera.fy = 50.0;
  input.camera.cx = 30.0;
  input.camera.cy = 20.0;
  input.camera.baseline = 0.5;
  input.camera.width = 60;
  input.camera.height = 40;
  input.T_cam_lidar = Eigen::Isometry3d::Identity();
  LidarPoint nan_point;
  nan_point.x = nan_point.y = nan_point.z = std::numeric_limits<float>::quiet_NaN();
  input.cloud.assign(1000, nan_point);
  FusionPipeline pipeline{FusionParams()};
  try {
    pipeline.process(input);
    FAIL() << "an all-NaN sweep was processed";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("none of the 1000 LiDAR points is finite"),
              std::string::npos)
        << e.what();
  }
  LidarPoint behind;  // finite, behind the camera
  behind.z = -5.f;
  input.cloud.push_back(behind);
  try {
    pipeline.process(input);
    FAIL() << "a sweep with no point in the image was processed";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("(1001 points, 1000 of them not finite, 0 in front"),
              std::string::npos)
        << e.what();
  }
}

/// `lasers` lasers stored laser by laser as in a KITTI .bin (ring 0 the highest), `per_laser`
/// points each, all 10 m from one origin.
LidarCloud sweepOrderCloud(int lasers, int per_laser) {
  LidarCloud cloud;
  for (int laser = 0; laser < lasers; ++laser) {
    const double elevation = (2.0 - 0.4 * laser) * M_PI / 180.0;
    for (int k = 0; k < per_laser; ++k) {
      double azimuth = 0.3 * M_PI / 180.0 + k * (2 * M_PI - 0.6 * M_PI / 180.0) / per_laser;
      if (azimuth > M_PI) azimuth -= 2 * M_PI;
      LidarPoint p;
      p.x = static_cast<float>(10 * std::cos(elevation) * std::cos(azimuth));
      p.y = static_cast<float>(10 * std::cos(elevation) * std::sin(azimuth));
      p.z = static_cast<float>(10 * std::sin(elevation));
      cloud.push_back(p);
    }
  }
  return cloud;
}

// Point 6: a sweep without rings (kitti2bag) gets its rings by sweep order as offline; a ring
// field that is all 0 is not believed; a shuffled sweep falls back to the beam model (issue 31)
// and never reaches the 32767-ring limit of the ring map.
TEST(Robustness, RingRecoveryFallsBackExplicitlyAndChecksPlausibility) {
  LidarCloud cloud = sweepOrderCloud(64, 500);
  RingRecovery r = ensureRings(cloud, false, 64);
  EXPECT_EQ(r.source, RingSource::kSweepOrder);
  EXPECT_EQ(r.rings, 64);
  EXPECT_TRUE(r.plausible);
  EXPECT_EQ(r.fallbacks, "");
  EXPECT_EQ(cloud[500].ring, 1);

  // A believable ring field is kept as it is.
  LidarCloud with_field = sweepOrderCloud(64, 500);
  for (std::size_t i = 0; i < with_field.size(); ++i) with_field[i].ring = 63 - int(i / 500);
  r = ensureRings(with_field, true, 64);
  EXPECT_EQ(r.source, RingSource::kField);
  EXPECT_EQ(r.rings, 64);
  EXPECT_EQ(with_field.front().ring, 63);

  LidarCloud zeros = sweepOrderCloud(64, 500);
  for (auto& p : zeros) p.ring = 0;
  r = ensureRings(zeros, true, 64);
  EXPECT_NE(r.source, RingSource::kField);
  EXPECT_EQ(r.rings, 64);
  EXPECT_NE(r.fallbacks.find("ring field: 1 ring for 32000 points"), std::string::npos)
      << r.fallbacks;

  LidarCloud shuffled = sweepOrderCloud(64, 3000);
  std::mt19937 rng(7);
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  r = ensureRings(shuffled, false, 64);
  EXPECT_EQ(r.source, RingSource::kBeamModel) << "seed 7";
  EXPECT_EQ(r.rings, 64);
  EXPECT_TRUE(r.plausible) << r.fallbacks;
  EXPECT_NE(r.fallbacks.find("sweep order: "), std::string::npos) << r.fallbacks;
  StereoCamera camera;
  camera.fx = camera.fy = 100;
  camera.cx = 50;
  camera.cy = 40;
  camera.baseline = 0.5;
  camera.width = 100;
  camera.height = 80;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  EXPECT_NO_THROW(projectCloud(shuffled, T, camera, ProjectionParams()));

  // One beam: the beam model and elevation find one ring; flagged as implausible, used anyway.
  LidarCloud flat = sweepOrderCloud(1, 2000);
  std::shuffle(flat.begin(), flat.end(), rng);
  r = ensureRings(flat, false, 64);
  EXPECT_FALSE(r.plausible);
  EXPECT_EQ(r.rings, 1);
  EXPECT_NE(r.fallbacks.find("beam model: 1 beam line for 2000 points"), std::string::npos)
      << r.fallbacks;
  EXPECT_NE(r.fallbacks.find("elevation: "), std::string::npos) << r.fallbacks;
  EXPECT_THROW(ensureRings(flat, false, 0), std::invalid_argument);
}

class TempDir {
 public:
  TempDir() : path_(fs::temp_directory_path() / ("lsf_robust_dir_" + std::to_string(::getpid()))) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// Point 7: a 16-bit pair was cut to 8 bits without a word (all black); now it is scaled.
TEST(Robustness, SixteenBitPngsAreScaledNotCut) {
  TempDir dir;
  cv::Mat3b image8(30, 40);
  cv::randu(image8, cv::Scalar::all(0), cv::Scalar::all(256));
  cv::Mat image16;
  image8.convertTo(image16, CV_16UC3, 257.0);  // 255 -> 65535
  kitti::Frame frame;
  frame.name = "0000000000";
  frame.left_image = (dir.path() / "left.png").string();
  frame.right_image = (dir.path() / "right.png").string();
  frame.velodyne = (dir.path() / "sweep.bin").string();
  ASSERT_TRUE(cv::imwrite(frame.left_image, image16));
  cv::Mat grey16;
  cv::cvtColor(image16, grey16, cv::COLOR_BGR2GRAY);
  ASSERT_TRUE(cv::imwrite(frame.right_image, grey16));
  kitti::writeVelodyneBin(frame.velodyne, sweepOrderCloud(4, 100));
  const kitti::FrameData data = kitti::loadFrame(frame, StereoCamera());
  ASSERT_EQ(data.left.type(), CV_8UC3);
  ASSERT_EQ(data.right.type(), CV_8UC3);
  EXPECT_EQ(cv::norm(data.left, image8, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(data.right, cv::NORM_INF), 100.0) << "cut to the low byte";
}

// Points 5 and 10 in the KITTI calibration: S_rect_02 4294968538 was read as 1242 (int wrap);
// a P_rect_03 in millimetres gave a 1000x baseline.
TEST(Robustness, KittiCalibrationSizeThatWrapsAndMillimetreBaselineAreErrors) {
  TempDir dir;
  const auto write = [&](const std::string& p3, const std::string& size) {
    std::ofstream(dir.path() / "calib_cam_to_cam.txt")
        << "R_rect_00: 1 0 0 0 1 0 0 0 1\nP_rect_02: 60 0 40 3 0 60 30 0 0 0 1 0\n"
        << "P_rect_03: " << p3 << "\nS_rect_02: " << size << "\n";
    std::ofstream(dir.path() / "calib_velo_to_cam.txt") << "R: 0 -1 0 0 0 -1 1 0 0\nT: 0 0 0\n";
  };
  const auto error = [&]() -> std::string {
    try {
      kitti::readCalibration(dir.path().string());
    } catch (const std::exception& e) {
      return e.what();
    }
    return "";
  };
  write("60 0 40 -27 0 60 30 0 0 0 1 0", "80 60");
  EXPECT_EQ(error(), "");
  write("60 0 40 -27 0 60 30 0 0 0 1 0", "4294968538 375");
  EXPECT_NE(error().find("S_rect_02"), std::string::npos) << error();
  write("60 0 40 -29997 0 60 30 0 0 0 1 0", "80 60");  // 500 m
  EXPECT_NE(error().find("millimetres"), std::string::npos) << error();
}

}  // namespace
}  // namespace lidar_stereo_fusion
