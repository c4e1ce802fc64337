// KITTI raw I/O on synthetic files with known contents: calibration conventions, .bin sweeps,
// depth PNGs, frame listing, timestamps.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include <unistd.h>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "lidar_stereo_fusion/io/kitti.h"

namespace lidar_stereo_fusion {
namespace {

namespace fs = std::filesystem;

/// A fresh, empty folder under the system temp dir, removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() / ("lsf_kitti_" + std::string(info->test_suite_name()) + "_" +
                                         info->name() + "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  fs::path operator/(const std::string& name) const { return path_ / name; }
  std::string str() const { return path_.string(); }

 private:
  fs::path path_;
};

void writeText(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

std::string join(const Eigen::MatrixXd& m) {
  std::ostringstream out;
  out.precision(17);
  for (int r = 0; r < m.rows(); ++r) {
    for (int c = 0; c < m.cols(); ++c) out << " " << m(r, c);
  }
  return out.str();
}

/// A synthetic KITTI calibration with known values (a tilted rig, cam 2 and cam 3 shifted in x,
/// y and z like the real P_rect_02/03, which carry small y and z terms).
struct SyntheticCalib {
  Eigen::Matrix3d k;
  Eigen::Vector3d t2{0.06, 0.0003, 0.0027};
  Eigen::Vector3d t3{-0.47, 0.0003, 0.0027};
  Eigen::Matrix3d r_rect, r_velo;
  Eigen::Vector3d t_velo{-0.004, -0.076, -0.27};

  SyntheticCalib() {
    k << 721.5, 0, 609.5, 0, 720.0, 172.8, 0, 0, 1;
    r_rect = Eigen::AngleAxisd(0.01, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
    // Velodyne x forward, y left, z up -> camera x right, y down, z forward, slightly rotated.
    Eigen::Matrix3d axes;
    axes << 0, -1, 0, 0, 0, -1, 1, 0, 0;
    r_velo = Eigen::AngleAxisd(0.02, Eigen::Vector3d(0.3, 1, -0.2).normalized()) * axes;
  }
  Eigen::Matrix<double, 3, 4> projection(const Eigen::Vector3d& t) const {
    Eigen::Matrix<double, 3, 4> p;
    p << k, k * t;
    return p;
  }
  double baseline() const { return t2.x() - t3.x(); }

  void write(const fs::path& dir, const std::string& drop_key = "",
             const std::string& bad_key = "") const {
    auto line = [&](const std::string& key, const std::string& values) {
      if (key == drop_key) return std::string();
      return key + ":" + (key == bad_key ? std::string(" 1 2 x3") : values) + "\n";
    };
    writeText(dir / "calib_cam_to_cam.txt",
              "calib_time: 09-Jan-2012 13:57:47\n" + line("R_rect_00", join(r_rect)) +
                  line("P_rect_02", join(projection(t2))) +
                  line("P_rect_03", join(projection(t3))) + line("S_rect_02", " 1242 375"));
    writeText(dir / "calib_velo_to_cam.txt", "calib_time: 15-Mar-2012 11:37:16\n" +
                                                 line("R", join(r_velo)) + line("T", join(t_velo)));
  }
};

TEST(KittiCalibration, IntrinsicsAndBaselineComeFromTheRectifiedProjections) {
  TempDir dir;
  const SyntheticCalib truth;
  truth.write(dir / "");
  const kitti::Calibration calib = kitti::readCalibration(dir.str());
  EXPECT_DOUBLE_EQ(calib.camera.fx, 721.5);
  EXPECT_DOUBLE_EQ(calib.camera.fy, 720.0);
  EXPECT_DOUBLE_EQ(calib.camera.cx, 609.5);
  EXPECT_DOUBLE_EQ(calib.camera.cy, 172.8);
  EXPECT_NEAR(calib.camera.baseline, 0.53, 1e-12);
  EXPECT_EQ(calib.camera.width, 1242);
  EXPECT_EQ(calib.camera.height, 375);
  EXPECT_TRUE(calib.P2.isApprox(truth.projection(truth.t2), 1e-12));
  EXPECT_TRUE(calib.P3.isApprox(truth.projection(truth.t3), 1e-12));
}

TEST(KittiCalibration, TransformIsRectifiedCam2AndReproducesTheDevkitProjection) {
  TempDir dir;
  const SyntheticCalib truth;
  truth.write(dir / "");
  const kitti::Calibration calib = kitti::readCalibration(dir.str());
  const uint64_t seed = 7;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> lateral(-20, 20), forward(3, 80);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d velo(forward(rng), lateral(rng), lateral(rng) * 0.1);
    // Devkit: x = P_rect_02 * R_rect_00 * [R|T] * X (homogeneous).
    const Eigen::Vector3d rect0 = truth.r_rect * (truth.r_velo * velo + truth.t_velo);
    const Eigen::Vector3d devkit2 = truth.projection(truth.t2) * rect0.homogeneous();
    const Eigen::Vector3d devkit3 = truth.projection(truth.t3) * rect0.homogeneous();
    const Eigen::Vector3d cam = calib.T_cam_velo * velo;
    // The transform is exactly "rect0 + t2": same depth as the devkit, same pixel through K.
    ASSERT_NEAR(cam.z(), devkit2.z(), 1e-12) << "seed " << seed;
    const Eigen::Vector3d pixel = truth.k * cam / cam.z();
    ASSERT_NEAR(pixel.x(), devkit2.x() / devkit2.z(), 1e-9) << "seed " << seed;
    ASSERT_NEAR(pixel.y(), devkit2.y() / devkit2.z(), 1e-9) << "seed " << seed;
    // Disparity against camera 3's devkit pixel is fx * B / z (cam 3 shares y and z offsets).
    const double disparity = devkit2.x() / devkit2.z() - devkit3.x() / devkit3.z();
    ASSERT_NEAR(disparity, calib.camera.disparityFromDepth(cam.z()), 1e-9) << "seed " << seed;
  }
}

TEST(KittiCalibration, MissingOrMalformedKeysNameFileAndKey) {
  const SyntheticCalib truth;
  for (const std::string key : {"P_rect_02", "P_rect_03", "R_rect_00", "S_rect_02", "R", "T"}) {
    TempDir dir;
    truth.write(dir / "", key);
    try {
      kitti::readCalibration(dir.str());
      ADD_FAILURE() << "no exception for missing key " << key;
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("'" + key + "'"), std::string::npos) << what;
      EXPECT_NE(what.find("calib_"), std::string::npos) << what;
    }
  }
  TempDir dir;
  truth.write(dir / "", "", "P_rect_03");
  try {
    kitti::readCalibration(dir.str());
    ADD_FAILURE() << "no exception for a malformed P_rect_03";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'P_rect_03'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("x3"), std::string::npos) << e.what();
  }
}

TEST(KittiCalibration, MissingFileAndSwappedCamerasAreErrors) {
  TempDir dir;
  EXPECT_THROW(kitti::readCalibration(dir.str()), std::runtime_error);
  SyntheticCalib swapped;
  std::swap(swapped.t2, swapped.t3);  // cam 3 left of cam 2: negative baseline
  swapped.write(dir / "");
  EXPECT_THROW(kitti::readCalibration(dir.str()), std::runtime_error);
}

TEST(KittiVelodyne, BinRoundTripKeepsEveryValueAndLeavesRingsUnknown) {
  TempDir dir;
  LidarCloud cloud;
  for (int i = 0; i < 5; ++i) {
    LidarPoint p;
    p.x = 1.5f * i;
    p.y = -0.25f * i;
    p.z = 0.125f + i;
    p.intensity = 0.1f * i;
    p.ring = 3;  // not stored in a .bin
    cloud.push_back(p);
  }
  const std::string path = (dir / "sweep.bin").string();
  kitti::writeVelodyneBin(path, cloud);
  EXPECT_EQ(fs::file_size(path), 5u * 16u);
  const LidarCloud read = kitti::readVelodyneBin(path);
  ASSERT_EQ(read.size(), cloud.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].x, cloud[i].x);
    EXPECT_EQ(read[i].y, cloud[i].y);
    EXPECT_EQ(read[i].z, cloud[i].z);
    EXPECT_EQ(read[i].intensity, cloud[i].intensity);
    EXPECT_EQ(read[i].ring, -1);
  }
}

TEST(KittiVelodyne, SizeNotMultipleOf16AndMissingFileAreErrors) {
  TempDir dir;
  const std::string path = (dir / "bad.bin").string();
  std::ofstream(path, std::ios::binary).write("0123456789abcdefXYZ", 19);
  try {
    kitti::readVelodyneBin(path);
    ADD_FAILURE() << "no exception for a 19-byte .bin";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("multiple of 16"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_THROW(kitti::readVelodyneBin((dir / "none.bin").string()), std::runtime_error);
}

TEST(KittiDepthPng, RoundTripQuantisesToOne256thMetreAndMarksNoValueWithZero) {
  TempDir dir;
  cv::Mat1f depth(2, 4, 0.f);
  depth(0, 0) = 1.0f;                                     // 256
  depth(0, 1) = 12.3456f;                                 // round(3160.47) = 3160
  depth(0, 2) = std::numeric_limits<float>::quiet_NaN();  // none
  depth(0, 3) = -2.f;                                     // none
  depth(1, 0) = std::numeric_limits<float>::infinity();   // none
  depth(1, 1) = 1000.f;                                   // saturates at 65535
  depth(1, 2) = 0.001f;                                   // tiny but present: 1
  depth(1, 3) = 80.0f;                                    // 20480
  const std::string path = (dir / "d.png").string();
  kitti::writeDepthPng(path, depth);
  const cv::Mat raw = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(raw.type(), CV_16UC1);
  const cv::Mat_<uint16_t> r = raw;
  EXPECT_EQ(r(0, 0), 256);
  EXPECT_EQ(r(0, 1), 3160);
  EXPECT_EQ(r(0, 2), 0);
  EXPECT_EQ(r(0, 3), 0);
  EXPECT_EQ(r(1, 0), 0);
  EXPECT_EQ(r(1, 1), 65535);
  EXPECT_EQ(r(1, 2), 1);
  EXPECT_EQ(r(1, 3), 20480);
  const cv::Mat1f back = kitti::readDepthPng(path);
  EXPECT_FLOAT_EQ(back(0, 0), 1.0f);
  EXPECT_FLOAT_EQ(back(0, 1), 3160.f / 256.f);
  EXPECT_EQ(back(0, 2), 0.f);
  EXPECT_FLOAT_EQ(back(1, 1), 65535.f / 256.f);
  EXPECT_FLOAT_EQ(back(1, 3), 80.f);
}

TEST(KittiDepthPng, EightBitOrMissingOrCorruptPngsAreErrors) {
  TempDir dir;
  const std::string grey = (dir / "grey.png").string();
  cv::imwrite(grey, cv::Mat1b(3, 3, uint8_t{7}));
  EXPECT_THROW(kitti::readDepthPng(grey), std::runtime_error);
  EXPECT_THROW(kitti::readDepthPng((dir / "none.png").string()), std::runtime_error);
  const std::string corrupt = (dir / "corrupt.png").string();
  writeText(corrupt, "not a png");
  EXPECT_THROW(kitti::readDepthPng(corrupt), std::runtime_error);
  EXPECT_THROW(kitti::writeDepthPng((dir / "no_such_dir" / "d.png").string(), cv::Mat1f(2, 2, 1.f)),
               std::runtime_error);
}

TEST(KittiFrames, OnlyFramesWithBothImagesAndASweepAreListedInOrder) {
  TempDir dir;
  const cv::Mat image(4, 6, CV_8UC3, cv::Scalar(10, 20, 30));
  fs::create_directories(dir / "image_02/data");
  fs::create_directories(dir / "image_03/data");
  fs::create_directories(dir / "velodyne_points/data");
  for (const std::string name : {"0000000010", "0000000002", "0000000005"}) {
    cv::imwrite((dir / ("image_02/data/" + name + ".png")).string(), image);
    kitti::writeVelodyneBin((dir / ("velodyne_points/data/" + name + ".bin")).string(), {});
  }
  cv::imwrite((dir / "image_03/data/0000000010.png").string(), image);
  cv::imwrite((dir / "image_03/data/0000000002.png").string(), image);
  const auto frames = kitti::listFrames(dir.str());
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].name, "0000000002");
  EXPECT_EQ(frames[1].name, "0000000010");
  EXPECT_EQ(fs::path(frames[1].right_image), dir / "image_03/data/0000000010.png");
  EXPECT_EQ(fs::path(frames[1].velodyne), dir / "velodyne_points/data/0000000010.bin");
  EXPECT_THROW(kitti::listFrames((dir / "nowhere").string()), std::runtime_error);
}

TEST(KittiFrames, LoadFrameRejectsImagesOfDifferentSizesOrUnreadable) {
  TempDir dir;
  kitti::Frame frame{"0", (dir / "l.png").string(), (dir / "r.png").string(),
                     (dir / "v.bin").string()};
  cv::imwrite(frame.left_image, cv::Mat(4, 6, CV_8UC3, cv::Scalar::all(0)));
  cv::imwrite(frame.right_image, cv::Mat(4, 7, CV_8UC3, cv::Scalar::all(0)));
  kitti::writeVelodyneBin(frame.velodyne, {});
  StereoCamera camera;  // width 0: no size expectation
  try {
    kitti::loadFrame(frame, camera);
    ADD_FAILURE() << "no exception for images of different sizes";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("sizes differ"), std::string::npos) << e.what();
  }
  cv::imwrite(frame.right_image, cv::Mat(4, 6, CV_8UC3, cv::Scalar::all(0)));
  camera.width = 8;
  camera.height = 4;
  EXPECT_THROW(kitti::loadFrame(frame, camera), std::runtime_error);  // calibration says 8x4
  camera.width = 6;
  EXPECT_NO_THROW(kitti::loadFrame(frame, camera));
  writeText(frame.left_image, "garbage");
  EXPECT_THROW(kitti::loadFrame(frame, camera), std::runtime_error);
}

TEST(KittiFrames, CalibrationDirIsTheDriveParent) {
  EXPECT_EQ(kitti::calibrationDirOf("/a/2011_09_26/2011_09_26_drive_0009_sync"), "/a/2011_09_26");
  EXPECT_EQ(kitti::calibrationDirOf("/a/2011_09_26/2011_09_26_drive_0009_sync/"), "/a/2011_09_26");
  EXPECT_EQ(kitti::calibrationDirOf("drive"), ".");
}

TEST(KittiTimestamps, ParsedAsUtcSecondsWithNanosecondsEmptyLinesAreNan) {
  TempDir dir;
  const fs::path path = dir / "timestamps.txt";
  writeText(path,
            "1970-01-01 00:00:01.500000000\n2011-09-26 13:02:25.964389445\n\n"
            "2000-02-29 23:59:59\n");
  const std::vector<double> t = kitti::readTimestamps(path.string());
  ASSERT_EQ(t.size(), 4u);
  EXPECT_DOUBLE_EQ(t[0], 1.5);
  EXPECT_NEAR(t[1], 1317042145.0 + 0.964389445, 1e-6);  // calendar.timegm(2011, 9, 26, 13, 2, 25)
  EXPECT_TRUE(std::isnan(t[2]));                        // empty line: dropped sample
  EXPECT_DOUBLE_EQ(t[3], 951868799.0);                  // leap day
  writeText(path, "1970-01-01 00:00:01.5\n2011-09-26 13:02\n");
  try {
    kitti::readTimestamps(path.string());
    ADD_FAILURE() << "no exception for a malformed timestamp";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace lidar_stereo_fusion
