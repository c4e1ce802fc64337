// The synthetic scene generator: exact depth, disparity, LiDAR points and visibility flags,
// consistent stereo views, determinism by seed, and the KITTI raw export read back by io/kitti.
#include <gtest/gtest.h>
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/sim/kitti_export.h"
#include "lidar_stereo_fusion/sim/scene.h"
#include "lidar_stereo_fusion/sim/synthetic_frame.h"
#include "sim/small_sim_params.h"

namespace lsf = lidar_stereo_fusion;
namespace sim = lidar_stereo_fusion::sim;

namespace {

sim::SyntheticParams smallParams() { return lsf::test::smallSyntheticParams(); }

int addTexturedMaterial(sim::Scene& scene) {
  sim::Material m;
  m.albedo = Eigen::Vector3d(0.6, 0.5, 0.4);
  m.pattern = sim::Pattern::kNoise;
  m.contrast = 0.5;
  m.wavelength_m = 0.5;
  return scene.addMaterial(m);
}

/// The street-frame position of a LiDAR point.
Eigen::Vector3d toWorld(const sim::SyntheticFrame& f, const lsf::LidarPoint& p) {
  return f.T_world_cam * f.T_cam_lidar * Eigen::Vector3d(p.x, p.y, p.z);
}

}  // namespace

TEST(SyntheticScene, SlantedPlaneDepthIsAnalytic) {
  sim::Scene scene(3);
  // Plane through (0, 0, 20) m, tilted so that depth varies along both image axes.
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, -0.3, -1.0).normalized();
  const double c = n.dot(Eigen::Vector3d(0, 0, 20));
  scene.addPlane(n, c, Eigen::Vector3d::UnitX(), addTexturedMaterial(scene));
  const sim::SyntheticParams p = smallParams();
  const sim::SyntheticFrame f = sim::renderFrame(scene, p, 0);
  for (int v = 0; v < p.height; ++v) {
    for (int u = 0; u < p.width; ++u) {
      // Ray X = z * r with r = ((u - cx) / fx, (v - cy) / fy, 1): n . (z r) = c.
      const Eigen::Vector3d r((u - p.cx) / p.fx, (v - p.cy) / p.fy, 1.0);
      const double z = c / n.dot(r);
      ASSERT_NEAR(f.depth(v, u), z, 1e-6 * z) << "pixel " << u << ", " << v;
      ASSERT_NEAR(f.disparity(v, u), p.fx * p.baseline / z, 1e-6 * p.fx * p.baseline / z)
          << "pixel " << u << ", " << v;
    }
  }
}

TEST(SyntheticScene, GroundPlaneDepthAndSky) {
  sim::Scene scene(4);
  const double height = 1.5;  // camera above the ground [m]
  scene.addPlane(Eigen::Vector3d(0, -1, 0), -height, Eigen::Vector3d::UnitX(),
                 addTexturedMaterial(scene));
  const sim::SyntheticParams p = smallParams();
  const sim::SyntheticFrame f = sim::renderFrame(scene, p, 0);
  for (int v = 0; v < p.height; ++v) {
    for (int u = 0; u < p.width; ++u) {
      if (v < p.cy) {
        ASSERT_EQ(f.depth(v, u), 0.f) << "sky pixel " << u << ", " << v;
        ASSERT_EQ(f.disparity(v, u), 0.f) << "sky pixel " << u << ", " << v;
      } else {
        const double z = height / ((v - p.cy) / p.fy);
        ASSERT_NEAR(f.depth(v, u), z, 1e-6 * z) << "pixel " << u << ", " << v;
      }
    }
  }
}

TEST(SyntheticScene, StreetDisparityIsFxBOverZ) {
  const uint64_t seed = 2;
  sim::SyntheticParams p = sim::SyntheticParams().resized(310, 94);
  p.seed = seed;
  const sim::SyntheticFrame f = sim::generateStreetFrame(p, 0);
  int sky = 0, ground_truth = 0, van = 0;
  for (int v = 0; v < p.height; ++v) {
    for (int u = 0; u < p.width; ++u) {
      const float z = f.depth(v, u), d = f.disparity(v, u);
      if (z == 0.f) {
        ++sky;
        ASSERT_EQ(d, 0.f) << "seed " << seed << " pixel " << u << ", " << v;
        continue;
      }
      ++ground_truth;
      van += f.low_texture(v, u) ? 1 : 0;
      ASSERT_GT(z, 1.0f) << "seed " << seed;
      ASSERT_NEAR(d, p.fx * p.baseline / z, 1e-5 * d) << "seed " << seed << " pixel " << u;
    }
  }
  // The scene has sky, mostly surfaces, and a visible low-texture region.
  EXPECT_GT(sky, 0) << "seed " << seed;
  EXPECT_GT(ground_truth, 0.8 * p.width * p.height) << "seed " << seed;
  EXPECT_GT(van, 200) << "seed " << seed;
}

TEST(SyntheticScene, StereoViewsMatchAtTheTrueDisparity) {
  sim::Scene scene(5);
  const sim::SyntheticParams p = smallParams();
  const int d = 8;  // [px], exact: the plane sits at z = fx B / d
  scene.addPlane(Eigen::Vector3d(0, 0, 1), p.fx * p.baseline / d, Eigen::Vector3d::UnitX(),
                 addTexturedMaterial(scene));
  sim::SyntheticParams aa = p;
  aa.subsamples = 2;
  for (const sim::SyntheticParams& params : {p, aa}) {
    const sim::SyntheticFrame f = sim::renderFrame(scene, params, 0);
    int max_diff = 0;
    for (int v = 0; v < p.height; ++v) {
      for (int u = d; u < p.width; ++u) {
        const cv::Vec3b a = f.left.at<cv::Vec3b>(v, u), b = f.right.at<cv::Vec3b>(v, u - d);
        for (int c = 0; c < 3; ++c) max_diff = std::max(max_diff, std::abs(a[c] - b[c]));
      }
    }
    // Same surface points, same shading: equal up to rounding of the 8-bit value.
    EXPECT_LE(max_diff, 1) << "subsamples " << params.subsamples;
    // And the texture is real: neighbouring pixels differ.
    cv::Mat grey;
    cv::cvtColor(f.left, grey, cv::COLOR_BGR2GRAY);
    cv::Scalar mean, stddev;
    cv::meanStdDev(grey, mean, stddev);
    EXPECT_GT(stddev[0], 5.0) << "subsamples " << params.subsamples;
  }
}

TEST(SyntheticScene, LidarPointsLieOnSurfacesAlongTheirBeams) {
  sim::Scene scene(6);
  const int material = addTexturedMaterial(scene);
  const double height = 1.65, wall_z = 30.0;
  scene.addPlane(Eigen::Vector3d(0, -1, 0), -height, Eigen::Vector3d::UnitX(), material);
  scene.addPlane(Eigen::Vector3d(0, 0, 1), wall_z, Eigen::Vector3d::UnitX(), material);
  for (int rings : {64, 128}) {
    sim::SyntheticParams p = smallParams();
    p.rings = rings;
    const sim::SyntheticFrame f = sim::renderFrame(scene, p, 2);  // the rig has moved 2 m
    const sim::LidarModel model = p.lidarModel();
    ASSERT_FALSE(f.cloud.empty());
    std::set<int> rings_seen;
    for (size_t i = 0; i < f.cloud.size(); ++i) {
      const lsf::LidarPoint& pt = f.cloud[i];
      const Eigen::Vector3d w = toWorld(f, pt);
      const double range = Eigen::Vector3d(pt.x, pt.y, pt.z).norm();
      const double tolerance = 1e-6 * range + 1e-5;  // float coordinates
      const bool on_ground = std::abs(w.y() - height) < tolerance;
      const bool on_wall = std::abs(w.z() - wall_z) < tolerance;
      ASSERT_TRUE(on_ground || on_wall)
          << rings << " rings, point " << i << " at " << w.transpose();
      ASSERT_GE(pt.ring, 0);
      ASSERT_LT(pt.ring, rings);
      const double elevation = std::atan2(pt.z, std::hypot(pt.x, pt.y)) * 180.0 / M_PI;
      ASSERT_NEAR(elevation, model.elevations_deg[pt.ring], 1e-4) << "point " << i;
      ASSERT_GE(pt.time, 0.f);
      ASSERT_LT(pt.time, p.frame_period);
      rings_seen.insert(pt.ring);
    }
    EXPECT_EQ(static_cast<int>(rings_seen.size()), rings);
    // Ring 0 is the highest beam; rings are stored in order, azimuth rising from just above 0.
    EXPECT_EQ(f.cloud.front().ring, 0);
    EXPECT_GT(std::atan2(f.cloud.front().y, f.cloud.front().x), 0.0);
    EXPECT_EQ(f.cloud.back().ring, rings - 1);
    EXPECT_LT(std::atan2(f.cloud.back().y, f.cloud.back().x), 0.0);
  }
}

TEST(SyntheticScene, VisibilityFlagsMatchAHandMadeOccluder) {
  // A wall at z = 20 m and a thin box in front of it at z = 10 m. The LiDAR is mounted far from
  // the camera (0.5 m right, 0.3 m up, 1 m behind) so it sees much wall the camera cannot.
  sim::Scene scene(7);
  const int material = addTexturedMaterial(scene);
  const double wall_z = 20.0, front_z = 9.95, back_z = 10.05;
  const double x0 = -0.5, x1 = 1.5, y0 = -1.0, y1 = 0.6;  // box extent [m]
  scene.addPlane(Eigen::Vector3d(0, 0, 1), wall_z, Eigen::Vector3d::UnitX(), material);
  scene.addBox(Eigen::Vector3d(0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * (front_z + back_z)),
               Eigen::Vector3d(0.5 * (x1 - x0), 0.5 * (y1 - y0), 0.5 * (back_z - front_z)),
               Eigen::Matrix3d::Identity(), material);
  sim::SyntheticParams p = smallParams();
  p.azimuth_step_deg = 0.1;
  p.lidar_position = Eigen::Vector3d(0.5, -0.3, -1.0);
  const sim::SyntheticFrame f = sim::renderFrame(scene, p, 0);

  // Analytic: the camera (at the origin) sees a wall point P iff its ray misses the box, i.e.
  // crosses neither the front nor the back rectangle of the box.
  // Points stored as float are ~1e-6 m off the true surface point: skip the few whose answer
  // would flip within that distance (on a rectangle edge or a pixel rounding boundary).
  constexpr double kEdge = 1e-5;  // [m]
  auto distanceToEdge = [&](const Eigen::Vector3d& w, double z) {
    const double x = w.x() * z / w.z(), y = w.y() * z / w.z();
    return std::min({std::abs(x - x0), std::abs(x - x1), std::abs(y - y0), std::abs(y - y1)});
  };
  auto inRectangle = [&](const Eigen::Vector3d& w, double z) {
    const double x = w.x() * z / w.z(), y = w.y() * z / w.z();
    return x >= x0 && x <= x1 && y >= y0 && y <= y1;
  };
  auto nearRoundingBoundary = [](double pixel) {
    return std::abs(pixel + 0.5 - std::round(pixel + 0.5)) < 1e-4;
  };
  int hidden = 0, visible = 0, on_box = 0;
  for (size_t i = 0; i < f.cloud.size(); ++i) {
    const Eigen::Vector3d w = toWorld(f, f.cloud[i]);
    const sim::PointTruth& t = f.truth[i];
    const double u = p.fx * w.x() / w.z() + p.cx, v = p.fy * w.y() / w.z() + p.cy;
    if (nearRoundingBoundary(u) || nearRoundingBoundary(v)) continue;
    if (distanceToEdge(w, front_z) < kEdge || distanceToEdge(w, back_z) < kEdge) continue;
    const bool in_image = w.z() > 0 && std::floor(u + 0.5) >= 0 && std::floor(u + 0.5) < p.width &&
                          std::floor(v + 0.5) >= 0 && std::floor(v + 0.5) < p.height;
    ASSERT_EQ(t.in_image, in_image) << "point " << i << " at " << w.transpose();
    ASSERT_NEAR(t.depth, w.z(), 1e-4 * std::abs(w.z()) + 1e-5);
    if (!in_image) continue;
    bool expected = true;
    if (std::abs(w.z() - wall_z) < 1e-3) {
      expected = !inRectangle(w, front_z) && !inRectangle(w, back_z);
    } else {
      ASSERT_NEAR(w.z(), front_z, 1e-4) << "the LiDAR can only see the box's front face";
      ++on_box;
    }
    ASSERT_EQ(t.visible, expected) << "point " << i << " at " << w.transpose();
    (expected ? visible : hidden) += 1;
  }
  EXPECT_GT(hidden, 100);
  EXPECT_GT(visible, 1000);
  EXPECT_GT(on_box, 100);
}

TEST(SyntheticScene, DeterministicBySeedAndThreadCount) {
  sim::SyntheticParams p = sim::SyntheticParams().resized(200, 60);
  p.azimuth_step_deg = 0.4;
  p.range_noise_sigma = 0.02;
  p.dropout_probability = 0.05;
  p.seed = 11;
  const sim::SyntheticFrame a = sim::generateStreetFrame(p, 1);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const sim::SyntheticFrame b = sim::generateStreetFrame(p, 1);
  omp_set_num_threads(threads);
  p.seed = 12;
  const sim::SyntheticFrame c = sim::generateStreetFrame(p, 1);

  EXPECT_EQ(cv::norm(a.left, b.left, cv::NORM_INF), 0.0) << "seed 11";
  EXPECT_EQ(cv::norm(a.right, b.right, cv::NORM_INF), 0.0) << "seed 11";
  EXPECT_EQ(cv::norm(a.depth, b.depth, cv::NORM_INF), 0.0) << "seed 11";
  ASSERT_EQ(a.cloud.size(), b.cloud.size()) << "seed 11";
  for (size_t i = 0; i < a.cloud.size(); ++i) {
    ASSERT_EQ(std::memcmp(&a.cloud[i], &b.cloud[i], sizeof(lsf::LidarPoint)), 0) << "point " << i;
    ASSERT_EQ(a.truth[i].visible, b.truth[i].visible) << "point " << i;
  }
  // Another seed: other textures, other placement, other noise.
  EXPECT_GT(cv::norm(a.left, c.left, cv::NORM_L1), 0.0) << "seeds 11 and 12";
  EXPECT_GT(cv::norm(a.depth, c.depth, cv::NORM_L1), 0.0) << "seeds 11 and 12";
  // Dropouts remove about 5 % of the returns.
  sim::SyntheticParams exact = p;
  exact.seed = 11;
  exact.dropout_probability = 0.0;
  exact.range_noise_sigma = 0.0;
  const double kept =
      static_cast<double>(a.cloud.size()) / sim::generateStreetFrame(exact, 1).cloud.size();
  EXPECT_NEAR(kept, 0.95, 0.01) << "seed 11";
}

TEST(SyntheticScene, KittiExportReadsBackWithTheKittiReader) {
  const uint64_t seed = 3;
  sim::SyntheticParams p = sim::SyntheticParams().resized(310, 94);
  p.seed = seed;
  p.azimuth_step_deg = 0.3;
  sim::KittiExportOptions options;
  options.num_frames = 2;
  const std::filesystem::path root = std::filesystem::temp_directory_path() /
                                     ("lsf_synthetic_kitti_" + std::to_string(::getpid()));
  std::filesystem::remove_all(root);
  const std::string drive = sim::writeKittiDrive(root.string(), p, options);
  EXPECT_EQ(std::filesystem::path(drive).filename(), "2000_01_01_drive_0001_sync");

  const lsf::kitti::Calibration calib =
      lsf::kitti::readCalibration(lsf::kitti::calibrationDirOf(drive));
  const lsf::StereoCamera expected = p.camera();
  EXPECT_NEAR(calib.camera.fx, expected.fx, 1e-6 * expected.fx);
  EXPECT_NEAR(calib.camera.fy, expected.fy, 1e-6 * expected.fy);
  EXPECT_NEAR(calib.camera.cx, expected.cx, 1e-6 * expected.cx);
  EXPECT_NEAR(calib.camera.cy, expected.cy, 1e-6 * expected.cy);
  EXPECT_NEAR(calib.camera.baseline, expected.baseline, 1e-6);
  EXPECT_EQ(calib.camera.width, expected.width);
  EXPECT_EQ(calib.camera.height, expected.height);
  EXPECT_LT((calib.T_cam_velo.matrix() - p.cameraFromLidar().matrix()).cwiseAbs().maxCoeff(), 1e-6);

  const std::vector<lsf::kitti::Frame> frames = lsf::kitti::listFrames(drive);
  ASSERT_EQ(frames.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    const sim::SyntheticFrame f = sim::generateStreetFrame(p, i);
    const lsf::kitti::FrameData data = lsf::kitti::loadFrame(frames[i], calib.camera);
    EXPECT_EQ(cv::norm(data.left, f.left, cv::NORM_INF), 0.0) << "frame " << i;
    EXPECT_EQ(cv::norm(data.right, f.right, cv::NORM_INF), 0.0) << "frame " << i;
    ASSERT_EQ(data.cloud.size(), f.cloud.size()) << "frame " << i;
    for (size_t k = 0; k < f.cloud.size(); ++k) {
      ASSERT_EQ(data.cloud[k].x, f.cloud[k].x);
      ASSERT_EQ(data.cloud[k].intensity, f.cloud[k].intensity);
      // The .bin stores lasers in KITTI's order, so the sweep-order rule recovers our rings.
      ASSERT_EQ(data.cloud[k].ring, f.cloud[k].ring) << "frame " << i << " point " << k;
    }
    const cv::Mat1f depth =
        lsf::kitti::readDepthPng((std::filesystem::path(drive) / "proj_depth/groundtruth/image_02" /
                                  (frames[i].name + ".png"))
                                     .string());
    for (int v = 0; v < depth.rows; ++v) {
      for (int u = 0; u < depth.cols; ++u) {
        ASSERT_NEAR(depth(v, u), f.depth(v, u), 1.0 / 512 + 1e-6) << "seed " << seed;
      }
    }
  }
  const std::vector<double> stamps =
      lsf::kitti::readTimestamps(drive + "/velodyne_points/timestamps.txt");
  ASSERT_EQ(stamps.size(), 2u);
  EXPECT_NEAR(stamps[1] - stamps[0], p.frame_period, 1e-6);
  std::filesystem::remove_all(root);
}

TEST(SyntheticScene, RejectsImpossibleParameters) {
  sim::SyntheticParams p;
  p.rings = 32;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = sim::SyntheticParams();
  p.baseline = 0.0;
  EXPECT_THROW(sim::generateStreetFrame(p), std::invalid_argument);
  p = sim::SyntheticParams();
  p.dropout_probability = 1.0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  sim::Scene scene;
  EXPECT_THROW(scene.addBox(Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 0, 1),
                            Eigen::Matrix3d::Identity(), 0),
               std::invalid_argument);
  EXPECT_THROW(sim::LidarModel::forRings(16), std::invalid_argument);
}
