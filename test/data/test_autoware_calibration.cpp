// Autoware camera-LiDAR calibration files: the real calibrator outputs in
// ../shared/data/autoware_calibration prove the extrinsic's direction through their CalibData
// pairs; small synthetic files check the projection formula and the error messages.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <unistd.h>

#include "data/data_guard.h"
#include "lidar_stereo_fusion/io/calibration_autoware.h"

namespace lidar_stereo_fusion {
namespace {

namespace fs = std::filesystem;

const char* const kFiles[] = {"20191211_135728_autoware_lidar_camera_calibration.yaml",
                              "20200218_235918_autoware_lidar_camera_calibration.yaml"};

TEST(AutowareCalibrationData, FilesReadWithEveryKey) {
  LSF_REQUIRE_DATA("autoware_calibration");
  const size_t pairs[] = {9, 11};
  for (int i = 0; i < 2; ++i) {
    SCOPED_TRACE(kFiles[i]);
    const auto calib = readAutowareCalibration(test::dataPath("autoware_calibration/") + kFiles[i]);
    EXPECT_EQ(calib.image_size, cv::Size(1920, 1208));
    EXPECT_EQ(calib.dist_coeffs.total(), 5u);
    EXPECT_EQ(calib.dist_model, "plumb_bob");
    EXPECT_EQ(calib.calib_data.size(), pairs[i]);
    EXPECT_GT(calib.reprojection_error, 0.0);
    EXPECT_GT(calib.camera_matrix(0, 0), 900.0);
    EXPECT_TRUE(calib.T_lidar_cam.linear().isUnitary(1e-6));
  }
}

// The direction proof: with p_cam = CameraExtrinsicMat^-1 p_lidar and the distortion applied, the
// clicked pairs reproject with the error the calibrator itself reported; the other direction puts
// every clicked LiDAR point behind the camera.
TEST(AutowareCalibrationData, InverseExtrinsicReproducesTheStatedReprojectionError) {
  LSF_REQUIRE_DATA("autoware_calibration");
  for (const char* file : kFiles) {
    SCOPED_TRACE(file);
    const auto calib = readAutowareCalibration(test::dataPath("autoware_calibration/") + file);
    const double forward = meanReprojectionError(calib);
    std::cout << file << ": stated " << calib.reprojection_error << " px, CameraExtrinsicMat^-1 "
              << forward << " px";
    EXPECT_NEAR(forward, calib.reprojection_error, 0.01 * calib.reprojection_error);

    const Eigen::Isometry3d opposite = calib.T_lidar_cam;  // used as LiDAR -> camera: wrong
    for (const auto& pair : calib.calib_data) {
      EXPECT_LT((opposite * Eigen::Vector3d(pair.x, pair.y, pair.z)).z(), 0.0)
          << "the opposite direction should put every clicked point behind the camera";
    }
    EXPECT_GT(meanReprojectionError(calib, opposite), 10 * calib.reprojection_error);

    // Inverting only the rotation (a classic mistake) is far off too.
    Eigen::Isometry3d half = calib.T_lidar_cam;
    half.linear().transposeInPlace();
    const double half_error = meanReprojectionError(calib, half);
    EXPECT_GT(half_error, 10 * calib.reprojection_error);

    // And the distortion coefficients matter: without them the error at least doubles.
    AutowareCalibration pinhole = calib;
    pinhole.dist_coeffs = cv::Mat();
    const double pinhole_error = meanReprojectionError(pinhole);
    EXPECT_GT(pinhole_error, 2 * calib.reprojection_error);
    std::cout << ", rotation-only inverse " << half_error << " px, without distortion "
              << pinhole_error << " px\n";
  }
}

// ---- Synthetic files (no data needed) ----

class TempYaml {
 public:
  explicit TempYaml(const std::string& text) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = (fs::temp_directory_path() / ("lsf_autoware_" + std::string(info->name()) + "_" +
                                          std::to_string(::getpid()) + ".yaml"))
                .string();
    std::ofstream(path_) << text;
  }
  ~TempYaml() { fs::remove(path_); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

std::string matrixNode(const std::string& key, int rows, int cols, const std::string& data) {
  return key + ": !!opencv-matrix\n   rows: " + std::to_string(rows) +
         "\n   cols: " + std::to_string(cols) + "\n   dt: d\n   data: [ " + data + " ]\n";
}

/// Camera 2 m along LiDAR x, looking along LiDAR x (camera z = LiDAR x, camera x = -LiDAR y,
/// camera y = -LiDAR z).
std::string syntheticFile(const std::string& skip = "",
                          const std::string& extrinsic_row0 = "0, 0, 1, 2") {
  std::string text = "%YAML:1.0\n---\n";
  if (skip != "CameraExtrinsicMat") {
    text += matrixNode("CameraExtrinsicMat", 4, 4,
                       extrinsic_row0 + ", -1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 0, 1");
  }
  if (skip != "CameraMat")
    text += matrixNode("CameraMat", 3, 3, "1000, 0, 640, 0, 900, 360, 0, 0, 1");
  if (skip != "DistCoeff") text += matrixNode("DistCoeff", 1, 5, "0.1, -0.05, 0.001, 0.002, 0.01");
  if (skip != "ImageSize") text += "ImageSize: [ 1280, 720 ]\n";
  text += "UnknownExtra: 5\n";
  return text;
}

TEST(AutowareCalibration, ProjectionMatchesThePlumbBobFormula) {
  TempYaml file(syntheticFile());
  const auto calib = readAutowareCalibration(file.path());
  EXPECT_EQ(calib.reprojection_error, -1.0);  // absent
  EXPECT_EQ(calib.dist_model, "plumb_bob");   // absent: default
  EXPECT_TRUE(calib.calib_data.empty());
  // LiDAR point (12, -1, 0.5): camera frame = extrinsic^-1 * p = (1, -0.5, 10).
  const Eigen::Vector3d cam = cameraFromLidar(calib) * Eigen::Vector3d(12, -1, 0.5);
  EXPECT_TRUE(cam.isApprox(Eigen::Vector3d(1, -0.5, 10), 1e-12)) << cam.transpose();
  const double x = 0.1, y = -0.05, r2 = x * x + y * y;
  const double radial = 1 + 0.1 * r2 - 0.05 * r2 * r2 + 0.01 * r2 * r2 * r2;
  const double xd = x * radial + 2 * 0.001 * x * y + 0.002 * (r2 + 2 * x * x);
  const double yd = y * radial + 0.001 * (r2 + 2 * y * y) + 2 * 0.002 * x * y;
  const cv::Point2d pixel = projectToImage(calib, cam);
  EXPECT_NEAR(pixel.x, 1000 * xd + 640, 1e-9);
  EXPECT_NEAR(pixel.y, 900 * yd + 360, 1e-9);
  EXPECT_THROW(projectToImage(calib, Eigen::Vector3d(0, 0, -1)), std::invalid_argument);
  EXPECT_THROW(meanReprojectionError(calib), std::invalid_argument);  // no CalibData
}

TEST(AutowareCalibration, MissingKeysAndNonRigidExtrinsicsAreErrorsNamingTheKey) {
  for (const std::string key : {"CameraExtrinsicMat", "CameraMat", "DistCoeff", "ImageSize"}) {
    TempYaml file(syntheticFile(key));
    try {
      readAutowareCalibration(file.path());
      ADD_FAILURE() << "no exception without " << key;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("'" + key + "'"), std::string::npos) << e.what();
    }
  }
  TempYaml scaled(syntheticFile("", "0, 0, 2, 2"));
  EXPECT_THROW(readAutowareCalibration(scaled.path()), std::runtime_error);
  EXPECT_THROW(readAutowareCalibration("/nonexistent/calibration.yaml"), std::runtime_error);
}

// Found by fuzzing: OpenCV's YAML parser never returned on this binary file (control bytes, then a
// bracket sequence). Files with control bytes are refused before OpenCV sees them.
TEST(AutowareCalibration, BinaryFilesAreRefusedBeforeOpenCvParsesThem) {
  const std::string hang =
      std::string("%YAML:1.0\n---ta: [ 0, 0, 1, 2, -1, p, 0, 0, 0, -1, 0, 0, 0,  0,0, 9 ]\nC") +
      std::string("\x01\0\0\0", 4) + "ameraMael: plumb" + std::string(30, '\xa7') + "]" +
      std::string(5, '\xa7') + "45, 36400, 10, -1, -0.5 ]\n";
  TempYaml file(hang);
  try {
    readAutowareCalibration(file.path());
    ADD_FAILURE() << "a binary file was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not a text file (control byte 1 at offset"),
              std::string::npos)
        << e.what();
  }
}

// Found by fuzzing too: a text file on which OpenCV's YAML parser never returned (a bare "5, -1,"
// line before "---at:"). Lines the calibrator never writes are refused, naming the line.
TEST(AutowareCalibration, MalformedLayoutIsRefusedNamingTheLine) {
  TempYaml hang("%YAML:1.0s: 4\n   cols: 4\n5, -1,\n---at: !!opencv-matrix\n   rows: 4\n");
  try {
    readAutowareCalibration(hang.path());
    ADD_FAILURE() << "a malformed file was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("line 1 is not 'Key: value'"), std::string::npos)
        << e.what();
  }
  TempYaml bare("%YAML:1.0\n---\n5, -1,\nImageSize: [ 4, 4 ]\n");
  try {
    readAutowareCalibration(bare.path());
    ADD_FAILURE() << "a bare sequence line was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("line 3 is not 'Key: value' (5, -1,)"), std::string::npos)
        << e.what();
  }
  // Another hang found by fuzzing: indented lines with no key above them.
  TempYaml orphan("%YAML:1.0\n\n   \n   cols: 5\n   dt: d\n 1, -0.5 ]\n");
  try {
    readAutowareCalibration(orphan.path());
    ADD_FAILURE() << "indented lines without a key were accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("line 4 is indented but no 'Key: value' line"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace lidar_stereo_fusion
