// rostest (test/ros/calibration_publishers.test): the calibration publishers' static transforms,
// checked against the real calibration files in ../shared/data without the project's readers:
//  * Autoware: the CalibData LiDAR points, moved into the camera frame through TF and projected
//    with CameraMat/DistCoeff (cv::projectPoints), land on their clicked pixels with the mean
//    error the file states (ReprojectionError). The opposite direction misses by hundreds of px.
//  * KITTI: Velodyne points moved through TF equal T_cam_velo * p, and projected with the left
//    intrinsics they land where the devkit's P_rect_02 * R_rect_00 * [R | T] puts them.
//  * Bad files: the publishers exit with status 1 and name the file.
// Missing data fails under CI=true and skips otherwise.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <ros/topic.h>
#include <sensor_msgs/CameraInfo.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_ros/transform_listener.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "data/data_guard.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "run_command.h"

namespace fs = std::filesystem;

/// Fails (CI=true) or skips the current test when `path` does not exist.
#define REQUIRE_PATH(path)                                                          \
  do {                                                                              \
    if (!fs::exists(path)) {                                                        \
      if (::lidar_stereo_fusion::test::runningUnderCi()) {                          \
        FAIL() << "missing test data " << (path) << " (CI=true: data is required)"; \
      } else {                                                                      \
        GTEST_SKIP() << "missing test data " << (path) << " (set CI=true to fail)"; \
      }                                                                             \
    }                                                                               \
  } while (0)

namespace {

std::string privateParam(const std::string& name) {
  std::string value;
  if (!ros::param::get("~" + name, value)) ADD_FAILURE() << "test parameter ~" << name << " unset";
  return value;
}

tf2_ros::Buffer& tfBuffer() {
  static tf2_ros::Buffer buffer;
  static tf2_ros::TransformListener listener(buffer);
  return buffer;
}

/// T_target_source from TF (waits up to 15 s for the publishers to come up).
Eigen::Isometry3d lookup(const std::string& target, const std::string& source) {
  return tf2::transformToEigen(
      tfBuffer().lookupTransform(target, source, ros::Time(0), ros::Duration(15.0)));
}

/// The fields of an Autoware calibration file this test needs, read with OpenCV directly.
struct AutowareFile {
  cv::Mat1d camera_matrix, dist_coeffs, calib_data;  // calib_data rows: u, v, x, y, z
  cv::Size image_size;
  double reprojection_error = -1;
};

AutowareFile readAutowareFile(const std::string& path) {
  cv::FileStorage fs(path, cv::FileStorage::READ);
  AutowareFile file;
  cv::Mat camera, dist, data;
  fs["CameraMat"] >> camera;
  fs["DistCoeff"] >> dist;
  fs["CalibData"] >> data;
  std::vector<int> size;
  fs["ImageSize"] >> size;
  fs["ReprojectionError"] >> file.reprojection_error;
  camera.convertTo(file.camera_matrix, CV_64F);
  dist.convertTo(file.dist_coeffs, CV_64F);
  data.convertTo(file.calib_data, CV_64F);
  if (size.size() == 2) file.image_size = cv::Size(size[0], size[1]);
  return file;
}

/// Mean distance [px] between the clicked pixels and the projections of the LiDAR points moved
/// into the camera frame by `T_cam_lidar`; counts points behind the camera in `behind`.
double meanReprojection(const AutowareFile& file, const Eigen::Isometry3d& T_cam_lidar,
                        int* behind) {
  std::vector<cv::Point3d> in_camera;
  *behind = 0;
  for (int i = 0; i < file.calib_data.rows; ++i) {
    const Eigen::Vector3d p(file.calib_data(i, 2), file.calib_data(i, 3), file.calib_data(i, 4));
    const Eigen::Vector3d q = T_cam_lidar * p;
    if (q.z() <= 0) ++*behind;
    in_camera.emplace_back(q.x(), q.y(), q.z());
  }
  std::vector<cv::Point2d> pixels;
  cv::projectPoints(in_camera, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), file.camera_matrix,
                    file.dist_coeffs, pixels);
  double sum = 0;
  for (int i = 0; i < file.calib_data.rows; ++i) {
    sum += cv::norm(pixels[i] - cv::Point2d(file.calib_data(i, 0), file.calib_data(i, 1)));
  }
  return sum / file.calib_data.rows;
}

void checkAutoware(const std::string& path, const std::string& ns, const std::string& lidar,
                   const std::string& camera) {
  const AutowareFile file = readAutowareFile(path);
  ASSERT_GT(file.calib_data.rows, 3) << path;
  ASSERT_EQ(file.calib_data.cols, 5) << path;
  ASSERT_GE(file.reprojection_error, 0) << path;

  const Eigen::Isometry3d T_cam_lidar = lookup(camera, lidar);
  int behind = 0;
  const double error = meanReprojection(file, T_cam_lidar, &behind);
  EXPECT_EQ(behind, 0) << path;
  // The file's ReprojectionError is this very mean; TF (quaternion, doubles) keeps it to 1e-3 px.
  EXPECT_NEAR(error, file.reprojection_error, 1e-3) << path;
  // The test tells the directions apart: the inverse transform misses by hundreds of pixels.
  const double wrong = meanReprojection(file, T_cam_lidar.inverse(), &behind);
  EXPECT_GT(wrong, 100.0) << path;
  ::testing::Test::RecordProperty(ns + "_reprojection_px", std::to_string(error));
  std::printf(
      "%s: mean reprojection through TF %.4f px (file %.4f px, inverse direction %.1f px)\n",
      path.c_str(), error, file.reprojection_error, wrong);

  ros::NodeHandle nh;
  const auto info = ros::topic::waitForMessage<sensor_msgs::CameraInfo>("/" + ns + "/camera_info",
                                                                        nh, ros::Duration(15.0));
  ASSERT_TRUE(info) << "no latched camera_info on /" << ns << "/camera_info";
  EXPECT_EQ(info->header.frame_id, camera);
  EXPECT_EQ(static_cast<int>(info->width), file.image_size.width);
  EXPECT_EQ(static_cast<int>(info->height), file.image_size.height);
  EXPECT_EQ(info->distortion_model, "plumb_bob");
  for (int i = 0; i < 9; ++i) EXPECT_DOUBLE_EQ(info->K[i], file.camera_matrix(i / 3, i % 3));
  ASSERT_EQ(static_cast<int>(info->D.size()), static_cast<int>(file.dist_coeffs.total()));
  for (size_t i = 0; i < info->D.size(); ++i) {
    EXPECT_DOUBLE_EQ(info->D[i], file.dist_coeffs(static_cast<int>(i)));
  }
}

/// "key: numbers" of a KITTI calibration file, parsed here independently of io/kitti.h.
std::map<std::string, std::vector<double>> readKeyValues(const std::string& path) {
  std::map<std::string, std::vector<double>> values;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::istringstream numbers(line.substr(colon + 1));
    std::vector<double> v;
    double x = 0;
    while (numbers >> x) v.push_back(x);
    values[line.substr(0, colon)] = v;
  }
  return values;
}

}  // namespace

TEST(AutowareCalibrationPublisher, CalibDataReprojectsThroughTf_20191211) {
  const std::string path = privateParam("autoware_a");
  REQUIRE_PATH(path);
  checkAutoware(path, "a", "lidar_a", "camera_a");
}

TEST(AutowareCalibrationPublisher, CalibDataReprojectsThroughTf_20200218) {
  const std::string path = privateParam("autoware_b");
  REQUIRE_PATH(path);
  checkAutoware(path, "b", "lidar_b", "camera_b");
}

TEST(KittiCalibrationPublisher, TfMovesVelodynePointsByTCamVelo) {
  const std::string calib_dir = privateParam("kitti_calib_dir");
  const std::string drive_dir = privateParam("kitti_drive_dir");
  const std::string sweep = drive_dir + "/velodyne_points/data/0000000000.bin";
  REQUIRE_PATH(calib_dir);
  REQUIRE_PATH(sweep);

  const auto calib = lidar_stereo_fusion::kitti::readCalibration(calib_dir);
  const Eigen::Isometry3d T = lookup("kitti_left", "kitti_velodyne");
  // Devkit projection, from the raw files: u = P_rect_02 * R_rect_00 * [R | T] * p.
  const auto cam = readKeyValues(calib_dir + "/calib_cam_to_cam.txt");
  const auto velo = readKeyValues(calib_dir + "/calib_velo_to_cam.txt");
  ASSERT_EQ(cam.at("P_rect_02").size(), 12u);
  ASSERT_EQ(cam.at("R_rect_00").size(), 9u);
  const Eigen::Matrix<double, 3, 4, Eigen::RowMajor> P2(cam.at("P_rect_02").data());
  Eigen::Matrix4d R_rect = Eigen::Matrix4d::Identity();
  R_rect.topLeftCorner<3, 3>() =
      Eigen::Matrix<double, 3, 3, Eigen::RowMajor>(cam.at("R_rect_00").data());
  Eigen::Matrix4d Rt = Eigen::Matrix4d::Identity();
  Rt.topLeftCorner<3, 3>() = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>(velo.at("R").data());
  Rt.topRightCorner<3, 1>() = Eigen::Vector3d(velo.at("T").data());
  const Eigen::Matrix<double, 3, 4> devkit = P2 * R_rect * Rt;

  // TF carries a unit quaternion, i.e. the rotation nearest to R_rect_00 * R, whose 7-digit
  // entries are orthonormal only to ~1e-6: points may move by that relative amount (1e-6 rad,
  // 20 um at 20 m, 0.001 px), far below any direction or frame mistake (metres, hundreds of px).
  const auto cloud = lidar_stereo_fusion::kitti::readVelodyneBin(sweep);
  int compared = 0;
  double max_relative = 0, max_px = 0;
  for (size_t i = 0; i < cloud.size(); i += 97) {
    const Eigen::Vector3d p(cloud[i].x, cloud[i].y, cloud[i].z);
    const Eigen::Vector3d q = T * p;
    const double relative = (q - calib.T_cam_velo * p).norm() / std::max(1.0, p.norm());
    max_relative = std::max(max_relative, relative);
    ASSERT_LT(relative, 1e-5) << "point " << i;
    if (q.z() < 2.0) continue;
    const Eigen::Vector3d u = devkit * p.homogeneous();
    const double u_tf = P2(0, 0) * q.x() / q.z() + P2(0, 2);
    const double v_tf = P2(1, 1) * q.y() / q.z() + P2(1, 2);
    max_px = std::max({max_px, std::abs(u_tf - u.x() / u.z()), std::abs(v_tf - u.y() / u.z())});
    ASSERT_NEAR(u_tf, u.x() / u.z(), 0.01) << "point " << i;
    ASSERT_NEAR(v_tf, u.y() / u.z(), 0.01) << "point " << i;
    ++compared;
  }
  std::printf(
      "KITTI: TF vs T_cam_velo max relative difference %.2e, TF vs devkit projection max "
      "%.2e px over %d points\n",
      max_relative, max_px, compared);
  EXPECT_GT(compared, 300);
  // Straight ahead of the car is in front of the camera; the camera is ~0.27 m ahead of it.
  EXPECT_GT((T * Eigen::Vector3d(20, 0, 0)).z(), 19.5);

  // Right camera: baseline metres along the left camera's x axis.
  const Eigen::Isometry3d T_right_left = lookup("kitti_right", "kitti_left");
  const Eigen::Vector3d shift =
      T_right_left * Eigen::Vector3d(1, 2, 10) - Eigen::Vector3d(1, 2, 10);
  EXPECT_NEAR(shift.x(), -calib.camera.baseline, 1e-9);
  EXPECT_NEAR(shift.y(), 0.0, 1e-9);
  EXPECT_NEAR(shift.z(), 0.0, 1e-9);
  EXPECT_NEAR(calib.camera.baseline, 0.5327, 1e-3);
}

TEST(CalibrationPublishers, BadInputExitsWithStatusOneAndNamesTheFile) {
  const std::string scratch = std::string(LSF_BINARY_DIR) + "/test_calibration_publishers";
  fs::create_directories(scratch);

  const std::string missing = scratch + "/no_such_calibration.yaml";
  auto [status, output] = lidar_stereo_fusion::test::runCommand(
      "timeout 30 " LSF_AUTOWARE_PUBLISHER " __name:=bad_autoware_missing _calibration_file:=" +
      missing);
  EXPECT_EQ(status, 1) << output;
  EXPECT_NE(output.find(missing), std::string::npos) << output;

  // A YAML without the extrinsic: the message names the missing key.
  const std::string no_extrinsic = scratch + "/no_extrinsic.yaml";
  {
    std::ofstream out(no_extrinsic);
    out << "%YAML:1.0\n---\nCameraMat: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
           "   data: [ 1000., 0., 960., 0., 1000., 600., 0., 0., 1. ]\n"
           "ImageSize: [ 1920, 1208 ]\n";
  }
  std::tie(status, output) = lidar_stereo_fusion::test::runCommand(
      "timeout 30 " LSF_AUTOWARE_PUBLISHER " __name:=bad_autoware_key _calibration_file:=" +
      no_extrinsic);
  EXPECT_EQ(status, 1) << output;
  EXPECT_NE(output.find("CameraExtrinsicMat"), std::string::npos) << output;

  std::tie(status, output) = lidar_stereo_fusion::test::runCommand(
      "timeout 30 " LSF_AUTOWARE_PUBLISHER " __name:=bad_autoware_unset");
  EXPECT_EQ(status, 1) << output;
  EXPECT_NE(output.find("calibration_file"), std::string::npos) << output;

  const std::string no_calib_dir = scratch + "/no_such_kitti_date";
  std::tie(status, output) = lidar_stereo_fusion::test::runCommand(
      "timeout 30 " LSF_KITTI_PUBLISHER " __name:=bad_kitti _calib_dir:=" + no_calib_dir);
  EXPECT_EQ(status, 1) << output;
  EXPECT_NE(output.find(no_calib_dir), std::string::npos) << output;
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_calibration_publishers");
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
