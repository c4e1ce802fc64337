// Direction and content of the calibration messages, checked through tf2's own buffer (no ROS
// master needed): a transform looked up as (target = camera, source = LiDAR) must move LiDAR
// points into the camera frame exactly as the calibration's LiDAR -> camera transform does.
#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>
#include <tf2/buffer_core.h>
#include <tf2_eigen/tf2_eigen.h>

#include "lidar_stereo_fusion/ros/calibration_msgs.h"
#include "lidar_stereo_fusion/ros/kitti_ego_motion.h"

namespace lsf = lidar_stereo_fusion;

namespace {

/// A rigid transform with a rotation about a generic axis and a translation of a few decimetres.
Eigen::Isometry3d someTransform(double angle, const Eigen::Vector3d& axis,
                                const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  T.translation() = t;
  return T;
}

const Eigen::Vector3d kPoints[] = {
    {10.0, 2.0, -1.5}, {5.0, -3.0, 0.2}, {30.0, 0.0, 1.0}, {-4.0, 7.0, 2.5}};

/// T_target_source from a buffer holding `msg` as a static transform.
Eigen::Isometry3d lookup(const geometry_msgs::TransformStamped& msg, const std::string& target,
                         const std::string& source) {
  tf2::BufferCore buffer;
  buffer.setTransform(msg, "test", /*is_static=*/true);
  return tf2::transformToEigen(buffer.lookupTransform(target, source, ros::Time(0)));
}

lsf::StereoCamera kittiLikeCamera() {
  lsf::StereoCamera camera;
  camera.fx = 721.5377;
  camera.fy = 721.5377;
  camera.cx = 609.5593;
  camera.cy = 172.854;
  camera.baseline = 0.5327;
  camera.width = 1242;
  camera.height = 375;
  return camera;
}

}  // namespace

TEST(CalibrationMsgs, AutowareTransformMovesLidarPointsIntoTheCamera) {
  lsf::AutowareCalibration calib;
  // Camera 0.3 m above and 0.1 m ahead of the LiDAR, looking forward (optical z = LiDAR x).
  calib.T_lidar_cam = someTransform(0.3, {0.2, -1.0, 0.5}, {0.1, -0.05, 0.3});
  const auto msg = lsf::autowareLidarToCamera(calib, "lidar", "camera", ros::Time(5.0));
  EXPECT_EQ(msg.header.frame_id, "lidar");
  EXPECT_EQ(msg.child_frame_id, "camera");
  // The message carries the camera pose in the LiDAR frame: its translation is the camera centre.
  EXPECT_NEAR(msg.transform.translation.x, 0.1, 1e-12);
  EXPECT_NEAR(msg.transform.translation.y, -0.05, 1e-12);
  EXPECT_NEAR(msg.transform.translation.z, 0.3, 1e-12);

  const Eigen::Isometry3d T_cam_lidar = lookup(msg, "camera", "lidar");
  for (const Eigen::Vector3d& p : kPoints) {
    const Eigen::Vector3d expected = calib.T_lidar_cam.inverse() * p;
    EXPECT_LT((T_cam_lidar * p - expected).norm(), 1e-9) << "point " << p.transpose();
  }
  // The camera centre (LiDAR coordinates = the translation) is the camera frame's origin.
  EXPECT_LT((T_cam_lidar * calib.T_lidar_cam.translation()).norm(), 1e-9);
}

TEST(CalibrationMsgs, KittiLookupVelodyneToCameraGivesTCamVelo) {
  lsf::kitti::Calibration calib;
  calib.camera = kittiLikeCamera();
  // KITTI-like: Velodyne x forward, y left, z up -> optical x right, y down, z forward.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  T.translation() = Eigen::Vector3d(-0.004, -0.076, -0.272);
  calib.T_cam_velo = someTransform(0.01, {1, 2, 3}, {0, 0, 0}) * T;

  const auto msg = lsf::kittiVelodyneToCamera(calib, "velodyne", "cam", ros::Time(1.0));
  EXPECT_EQ(msg.header.frame_id, "velodyne");
  EXPECT_EQ(msg.child_frame_id, "cam");
  const Eigen::Isometry3d looked_up = lookup(msg, "cam", "velodyne");
  for (const Eigen::Vector3d& p : kPoints) {
    EXPECT_LT((looked_up * p - calib.T_cam_velo * p).norm(), 1e-9) << "point " << p.transpose();
  }
  // A point straight ahead of the Velodyne is in front of the camera (optical z > 0).
  EXPECT_GT((looked_up * Eigen::Vector3d(20, 0, 0)).z(), 19.0);
}

TEST(CalibrationMsgs, RightCameraTransformAgreesWithRightCameraInfo) {
  const lsf::StereoCamera camera = kittiLikeCamera();
  const auto msg = lsf::stereoLeftToRight(camera, "left", "right", ros::Time(1.0));
  const Eigen::Isometry3d T_right_left = lookup(msg, "right", "left");
  const sensor_msgs::CameraInfo left = lsf::rectifiedCameraInfo(camera, "left", false);
  const sensor_msgs::CameraInfo right = lsf::rectifiedCameraInfo(camera, "right", true);
  EXPECT_DOUBLE_EQ(left.P[3], 0.0);
  EXPECT_DOUBLE_EQ(right.P[3], -camera.fx * camera.baseline);
  for (const Eigen::Vector3d& p_left : kPoints) {
    if (p_left.z() <= 0) continue;
    // image_geometry: u_right = (P_right * [p_left; 1]) for a point in the left (first) frame ...
    const double w = right.P[8] * p_left.x() + right.P[9] * p_left.y() + right.P[10] * p_left.z();
    const double u_p = (right.P[0] * p_left.x() + right.P[2] * p_left.z() + right.P[3]) / w;
    // ... = K * p_right with p_right from TF ...
    const Eigen::Vector3d p_right = T_right_left * p_left;
    const double u_tf = camera.fx * p_right.x() / p_right.z() + camera.cx;
    EXPECT_NEAR(u_p, u_tf, 1e-9);
    // ... = u_left - d with d = fx * B / z (the core's disparity convention).
    const double u_left = camera.fx * p_left.x() / p_left.z() + camera.cx;
    EXPECT_NEAR(u_left - u_tf, camera.disparityFromDepth(p_left.z()), 1e-9);
  }
}

TEST(CalibrationMsgs, RectifiedCameraInfoFields) {
  const lsf::StereoCamera camera = kittiLikeCamera();
  const sensor_msgs::CameraInfo info = lsf::rectifiedCameraInfo(camera, "left_opt", false);
  EXPECT_EQ(info.header.frame_id, "left_opt");
  EXPECT_EQ(info.width, 1242u);
  EXPECT_EQ(info.height, 375u);
  EXPECT_EQ(info.distortion_model, "plumb_bob");
  ASSERT_EQ(info.D.size(), 5u);
  for (double d : info.D) EXPECT_EQ(d, 0.0);
  const boost::array<double, 9> K = {camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1};
  EXPECT_EQ(info.K, K);
  const boost::array<double, 9> R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  EXPECT_EQ(info.R, R);
  EXPECT_DOUBLE_EQ(info.P[0], camera.fx);
  EXPECT_DOUBLE_EQ(info.P[2], camera.cx);
  EXPECT_DOUBLE_EQ(info.P[5], camera.fy);
  EXPECT_DOUBLE_EQ(info.P[6], camera.cy);
  EXPECT_DOUBLE_EQ(info.P[10], 1.0);

  lsf::StereoCamera bad = camera;
  bad.baseline = -1.0;
  EXPECT_THROW(lsf::rectifiedCameraInfo(bad, "x", true), std::invalid_argument);
}

TEST(CalibrationMsgs, AutowareCameraInfoFields) {
  lsf::AutowareCalibration calib;
  calib.T_lidar_cam = Eigen::Isometry3d::Identity();
  calib.camera_matrix = cv::Matx33d(1800, 0, 980, 0, 1810, 650, 0, 0, 1);
  calib.dist_coeffs = (cv::Mat1d(1, 5) << -0.3, 0.13, 0.001, 0.002, -0.02);
  calib.image_size = cv::Size(1920, 1208);
  calib.dist_model = "plumb_bob";
  const sensor_msgs::CameraInfo info = lsf::autowareCameraInfo(calib, "cam");
  EXPECT_EQ(info.header.frame_id, "cam");
  EXPECT_EQ(info.width, 1920u);
  EXPECT_EQ(info.height, 1208u);
  EXPECT_EQ(info.distortion_model, "plumb_bob");
  ASSERT_EQ(info.D.size(), 5u);
  EXPECT_DOUBLE_EQ(info.D[0], -0.3);
  EXPECT_DOUBLE_EQ(info.D[4], -0.02);
  const boost::array<double, 9> K = {1800, 0, 980, 0, 1810, 650, 0, 0, 1};
  EXPECT_EQ(info.K, K);
  const boost::array<double, 12> P = {1800, 0, 980, 0, 0, 1810, 650, 0, 0, 0, 1, 0};
  EXPECT_EQ(info.P, P);

  calib.image_size = cv::Size(0, 0);
  EXPECT_THROW(lsf::autowareCameraInfo(calib, "cam"), std::invalid_argument);
}

TEST(CalibrationMsgs, RejectsImpossibleTransforms) {
  Eigen::Isometry3d scaled = Eigen::Isometry3d::Identity();
  scaled.linear() *= 2.0;
  EXPECT_THROW(lsf::transformMsg(scaled, "a", "b", ros::Time(0)), std::invalid_argument);
  Eigen::Isometry3d mirrored = Eigen::Isometry3d::Identity();
  mirrored.linear()(0, 0) = -1.0;
  EXPECT_THROW(lsf::transformMsg(mirrored, "a", "b", ros::Time(0)), std::invalid_argument);
  Eigen::Isometry3d nan = Eigen::Isometry3d::Identity();
  nan.translation().x() = std::nan("");
  EXPECT_THROW(lsf::transformMsg(nan, "a", "b", ros::Time(0)), std::invalid_argument);
  const Eigen::Isometry3d identity = Eigen::Isometry3d::Identity();
  EXPECT_THROW(lsf::transformMsg(identity, "", "b", ros::Time(0)), std::invalid_argument);
  EXPECT_THROW(lsf::transformMsg(identity, "a", "a", ros::Time(0)), std::invalid_argument);
  EXPECT_NO_THROW(lsf::transformMsg(identity, "a", "b", ros::Time(0)));
}

// kitti_to_bag's ego-motion: imu -> velodyne is T_velo_imu^-1 (a tf2 lookup of the Velodyne in
// the IMU frame maps Velodyne points into IMU coordinates); odom -> imu poses relative to the first
// sample at the samples' stamps; the samples kept are those TF needs over [first, last].
TEST(CalibrationMsgs, KittiEgoMotionTransforms) {
  Eigen::Isometry3d T_velo_imu = Eigen::Isometry3d::Identity();
  T_velo_imu.linear() = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_velo_imu.translation() = Eigen::Vector3d(-0.8, 0.3, -0.8);
  const auto imu_velo = lsf::kittiImuToVelodyne(T_velo_imu, "imu_link", "velodyne", ros::Time(5));
  EXPECT_EQ(imu_velo.header.frame_id, "imu_link");
  EXPECT_EQ(imu_velo.child_frame_id, "velodyne");
  tf2::BufferCore buffer;
  buffer.setTransform(imu_velo, "test", true);
  const Eigen::Isometry3d T_imu_velo =
      tf2::transformToEigen(buffer.lookupTransform("imu_link", "velodyne", ros::Time(0)));
  EXPECT_TRUE((T_imu_velo * T_velo_imu).isApprox(Eigen::Isometry3d::Identity(), 1e-12));

  std::vector<lsf::kitti::OxtsSample> samples(5);
  for (size_t i = 0; i < samples.size(); ++i) {
    samples[i].name = std::to_string(i);
    samples[i].stamp = 100.0 + 0.1 * static_cast<double>(i);
    samples[i].packet.lat = 49.0;
    samples[i].packet.lon = 8.4 + 1e-5 * static_cast<double>(i);  // east, ~0.73 m apart
  }
  const auto kept = lsf::samplesBracketing(samples, 100.15, 100.25);
  ASSERT_EQ(kept.size(), 3u);  // 100.1 .. 100.3
  EXPECT_EQ(kept.front().name, "1");
  EXPECT_EQ(kept.back().name, "3");
  EXPECT_EQ(lsf::samplesBracketing(samples, 100.1, 100.2).size(), 2u);  // on the samples
  EXPECT_EQ(lsf::samplesBracketing(samples, 90.0, 110.0).size(), 5u);
  const auto tf = lsf::kittiEgoMotionTf(kept, "odom", "imu_link");
  ASSERT_EQ(tf.size(), 3u);
  EXPECT_EQ(tf[0].header.frame_id, "odom");
  EXPECT_EQ(tf[0].child_frame_id, "imu_link");
  EXPECT_EQ(tf[2].header.stamp, ros::Time(100.3));
  EXPECT_EQ(tf[0].transform.translation.x, 0.0);
  const double east = std::cos(49.0 * M_PI / 180.0) * 1e-5 * M_PI * 6378137.0 / 180.0;
  EXPECT_NEAR(tf[2].transform.translation.x, 2.0 * east, 1e-6);
  EXPECT_NEAR(tf[2].transform.translation.y, 0.0, 1e-6);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
