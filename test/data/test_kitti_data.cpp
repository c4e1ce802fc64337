// KITTI raw I/O on the real drive in ../shared/data/kitti_raw: calibration values, the
// LiDAR -> rectified cam 2 transform against the devkit's projection, the baseline proven
// photometrically, frame listing, sweeps and timestamps.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "data/data_guard.h"
#include "lidar_stereo_fusion/io/kitti.h"

namespace lidar_stereo_fusion {
namespace {

const char* const kDrive = "kitti_raw/2011_09_26/2011_09_26_drive_0009_sync";

TEST(KittiData, CalibrationOfTheDriveDate) {
  LSF_REQUIRE_DATA(kDrive);
  const auto calib = kitti::readCalibration(kitti::calibrationDirOf(test::dataPath(kDrive)));
  EXPECT_DOUBLE_EQ(calib.camera.fx, 721.5377);
  EXPECT_DOUBLE_EQ(calib.camera.fy, 721.5377);
  EXPECT_DOUBLE_EQ(calib.camera.cx, 609.5593);
  EXPECT_DOUBLE_EQ(calib.camera.cy, 172.854);
  EXPECT_NEAR(calib.camera.baseline, (44.85728 + 339.5242) / 721.5377, 1e-12);  // 0.5327 m
  EXPECT_EQ(calib.camera.width, 1242);
  EXPECT_EQ(calib.camera.height, 375);
  // The Velodyne sits behind and above the camera: its origin is at z ~ -0.27 m, y ~ -0.08 m in
  // the camera frame, and cam 2 is ~6 cm left of cam 0 (x ~ +0.06 m).
  const Eigen::Vector3d origin = calib.T_cam_velo.translation();
  EXPECT_NEAR(origin.x(), 0.057, 0.005);
  EXPECT_NEAR(origin.y(), -0.075, 0.005);
  EXPECT_NEAR(origin.z(), -0.27, 0.005);
}

TEST(KittiData, TransformReproducesTheDevkitProjectionOfTheRealSweep) {
  LSF_REQUIRE_DATA(kDrive);
  const std::string drive = test::dataPath(kDrive);
  const auto calib = kitti::readCalibration(kitti::calibrationDirOf(drive));
  const auto frames = kitti::listFrames(drive);
  ASSERT_FALSE(frames.empty());
  const LidarCloud cloud = kitti::readVelodyneBin(frames[0].velodyne);
  // Devkit: P_rect_02 * R_rect_00 * Tr_velo_to_cam = P2 * (T_cam_velo with t2 removed), i.e.
  // K [I | t2] applied to the rectified cam-0 coordinates. Recompute rect0 from T_cam_velo.
  const Eigen::Matrix3d k = calib.P2.leftCols<3>();
  const Eigen::Vector3d t2 = k.inverse() * calib.P2.col(3);
  int checked = 0;
  for (const LidarPoint& p : cloud) {
    const Eigen::Vector3d cam = calib.T_cam_velo * Eigen::Vector3d(p.x, p.y, p.z);
    if (cam.z() < 1.0) continue;
    const Eigen::Vector3d rect0 = cam - t2;
    const Eigen::Vector3d devkit2 = calib.P2 * rect0.homogeneous();
    const Eigen::Vector3d devkit3 = calib.P3 * rect0.homogeneous();
    const Eigen::Vector3d pixel = k * cam / cam.z();
    ASSERT_NEAR(pixel.x(), devkit2.x() / devkit2.z(), 1e-9);
    ASSERT_NEAR(pixel.y(), devkit2.y() / devkit2.z(), 1e-9);
    if (pixel.x() < 0 || pixel.x() > calib.camera.width || pixel.y() < 0 ||
        pixel.y() > calib.camera.height) {
      continue;
    }
    // Camera 3's devkit pixel is left by fx B / z, up to cam 3's 16 um depth offset in P_rect_03
    // (|u - cx| * 1.6e-5 / z < 0.015 / z px inside the image, and 1.4e-5 m of baseline).
    const double disparity = devkit2.x() / devkit2.z() - devkit3.x() / devkit3.z();
    const double expected = calib.camera.disparityFromDepth(cam.z());
    ASSERT_NEAR(disparity, expected, 0.015 / cam.z() + 1e-4 * expected);
    // Rows agree up to cam 3's 2.8 mm vertical offset in P_rect_03 (fy * 0.0028 / z px).
    ASSERT_NEAR(devkit2.y() / devkit2.z(), devkit3.y() / devkit3.z(), 2.1 / cam.z());
    ++checked;
  }
  EXPECT_GT(checked, 10000);  // points inside the image
}

/// Mean absolute grey difference between the left image at each LiDAR point (z >= 3 m) and the
/// right image at u - scale * fx B / z (bilinear).
double photometricError(const kitti::FrameData& data, const kitti::Calibration& calib,
                        double scale) {
  cv::Mat left, right;
  cv::cvtColor(data.left, left, cv::COLOR_BGR2GRAY);
  cv::cvtColor(data.right, right, cv::COLOR_BGR2GRAY);
  left.convertTo(left, CV_32F);
  right.convertTo(right, CV_32F);
  const StereoCamera& c = calib.camera;
  auto sample = [](const cv::Mat& image, double u, double v) {
    const int x = static_cast<int>(u), y = static_cast<int>(v);
    const double fx = u - x, fy = v - y;
    return (1 - fy) * ((1 - fx) * image.at<float>(y, x) + fx * image.at<float>(y, x + 1)) +
           fy * ((1 - fx) * image.at<float>(y + 1, x) + fx * image.at<float>(y + 1, x + 1));
  };
  double sum = 0;
  int count = 0;
  for (const LidarPoint& p : data.cloud) {
    const Eigen::Vector3d cam = calib.T_cam_velo * Eigen::Vector3d(p.x, p.y, p.z);
    if (cam.z() < 3.0) continue;
    const double u = c.fx * cam.x() / cam.z() + c.cx, v = c.fy * cam.y() / cam.z() + c.cy;
    const double ur = u - scale * c.disparityFromDepth(cam.z());
    if (u < 0 || v < 0 || ur < 0 || u >= c.width - 1 || ur >= c.width - 1 || v >= c.height - 1) {
      continue;
    }
    sum += std::abs(sample(left, u, v) - sample(right, ur, v));
    ++count;
  }
  return count > 0 ? sum / count : 1e9;
}

// The baseline and its sign, proven by the images: LiDAR points land on the same scene point in
// the right image exactly at disparity fx B / z; 10 % more or less, or the wrong sign, match worse.
TEST(KittiData, LidarDisparityMatchesTheImagesBestAtTheCalibratedBaseline) {
  LSF_REQUIRE_DATA(kDrive);
  const std::string drive = test::dataPath(kDrive);
  const auto calib = kitti::readCalibration(kitti::calibrationDirOf(drive));
  const auto frames = kitti::listFrames(drive);
  ASSERT_EQ(frames.size(), 11u);
  for (const auto& frame : frames) {
    const auto data = kitti::loadFrame(frame, calib.camera);
    const double at_one = photometricError(data, calib, 1.0);
    const double smaller = photometricError(data, calib, 0.9);
    const double larger = photometricError(data, calib, 1.1);
    const double flipped = photometricError(data, calib, -1.0);
    std::cout << frame.name << ": grey error at 0.9/1.0/1.1/-1 x disparity: " << smaller << " / "
              << at_one << " / " << larger << " / " << flipped << "\n";
    EXPECT_LT(at_one, smaller) << frame.name;
    EXPECT_LT(at_one, larger) << frame.name;
    EXPECT_LT(2 * at_one, flipped) << frame.name;
    EXPECT_LT(at_one, 15.0) << frame.name;  // grey levels 0..255
  }
}

TEST(KittiData, FramesSweepsAndTimestamps) {
  LSF_REQUIRE_DATA(kDrive);
  const std::string drive = test::dataPath(kDrive);
  const auto frames = kitti::listFrames(drive);
  ASSERT_EQ(frames.size(), 11u);  // 0, 5, ..., 50; sweeps 16-19 and 21-24 have no images
  for (size_t i = 0; i < frames.size(); ++i) {
    char name[16];
    std::snprintf(name, sizeof(name), "%010zu", 5 * i);
    EXPECT_EQ(frames[i].name, name);
    const LidarCloud cloud = kitti::readVelodyneBin(frames[i].velodyne);
    EXPECT_EQ(cloud.size() * 16, std::filesystem::file_size(frames[i].velodyne));
    EXPECT_GT(cloud.size(), 100000u);
  }
  const auto image_stamps = kitti::readTimestamps(drive + "/image_02/timestamps.txt");
  ASSERT_EQ(image_stamps.size(), 447u);
  EXPECT_NEAR(image_stamps[0], 1317042504.96793088, 1e-6) << "2011-09-26 13:08:24.967930880";
  for (size_t i = 1; i < image_stamps.size(); ++i) {
    EXPECT_NEAR(image_stamps[i] - image_stamps[i - 1], 0.1035, 0.001) << "line " << i + 1;
  }
  // The Velodyne file has empty lines for the dropped sweeps 177-180; indices stay aligned.
  const auto sweep_stamps = kitti::readTimestamps(drive + "/velodyne_points/timestamps.txt");
  ASSERT_EQ(sweep_stamps.size(), 447u);
  for (size_t i = 0; i < sweep_stamps.size(); ++i) {
    EXPECT_EQ(std::isnan(sweep_stamps[i]), i >= 177 && i <= 180) << "line " << i + 1;
    // Each sweep is stamped within 20 ms of its image (the camera triggers on the sweep).
    if (!std::isnan(sweep_stamps[i])) {
      EXPECT_NEAR(sweep_stamps[i], image_stamps[i], 0.02) << "line " << i + 1;
    }
  }
}

}  // namespace
}  // namespace lidar_stereo_fusion
