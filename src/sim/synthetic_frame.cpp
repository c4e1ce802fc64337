// Rendering of one synthetic frame: stereo pair, LiDAR sweep and exact ground truth.
#include "lidar_stereo_fusion/sim/synthetic_frame.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include "lidar_stereo_fusion/sim/random.h"
#include "lidar_stereo_fusion/sim/street_scene.h"

namespace lidar_stereo_fusion {
namespace sim {
namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("sim::SyntheticParams: " + what);
}

/// Unit direction of the ray through sub-pixel (x, y) of a camera aligned with the street frame.
Eigen::Vector3d pixelRay(const SyntheticParams& p, double x, double y) {
  return Eigen::Vector3d((x - p.cx) / p.fx, (y - p.cy) / p.fy, 1.0).normalized();
}

/// One view: subsamples^2 rays per pixel on a regular grid, averaged in linear RGB, gamma,
/// then Gaussian noise (a hash of seed, pixel and channel: identical for any thread count).
/// Textures are pre-filtered for the left camera at `filter_centre` in both views.
cv::Mat renderView(const Scene& scene, const SyntheticParams& p, const Eigen::Vector3d& centre,
                   const Eigen::Vector3d& filter_centre, uint64_t noise_seed) {
  cv::Mat image(p.height, p.width, CV_8UC3);
  const int s = p.subsamples;
#pragma omp parallel for schedule(dynamic, 2)
  for (int y = 0; y < p.height; ++y) {
    auto* row = image.ptr<cv::Vec3b>(y);
    for (int x = 0; x < p.width; ++x) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int sy = 0; sy < s; ++sy) {
        for (int sx = 0; sx < s; ++sx) {
          const double ox = (sx + 0.5) / s - 0.5, oy = (sy + 0.5) / s - 0.5;
          sum += scene.radiance(centre, pixelRay(p, x + ox, y + oy), filter_centre, p.fx);
        }
      }
      const Eigen::Vector3d rgb = sum / (s * s);
      const uint64_t pixel = static_cast<uint64_t>(y) * p.width + x;
      for (int c = 0; c < 3; ++c) {
        double value = 255.0 * std::pow(std::clamp(rgb[c], 0.0, 1.0), 1.0 / p.gamma);
        if (p.image_noise_sigma > 0.0) {
          const uint64_t key = hashCombine(noise_seed, pixel, static_cast<uint64_t>(c));
          value += p.image_noise_sigma * normalFromHashes(key, hashCombine(key, 1));
        }
        row[x][2 - c] = cv::saturate_cast<uint8_t>(value);  // RGB -> BGR
      }
    }
  }
  return image;
}

/// Depth, disparity, the low-texture mask and the LiDAR field-of-view mask from the ray through
/// each pixel centre.
void renderGroundTruth(const Scene& scene, const SyntheticParams& p, const Eigen::Vector3d& centre,
                       SyntheticFrame& frame) {
  frame.depth = cv::Mat1f(p.height, p.width, 0.f);
  frame.disparity = cv::Mat1f(p.height, p.width, 0.f);
  frame.low_texture = cv::Mat1b(p.height, p.width, uint8_t{0});
  frame.lidar_fov = cv::Mat1b(p.height, p.width, uint8_t{0});
  const LidarModel model = p.lidarModel();
  const auto [lowest, highest] =
      std::minmax_element(model.elevations_deg.begin(), model.elevations_deg.end());
  const double min_elevation = *lowest * M_PI / 180.0, max_elevation = *highest * M_PI / 180.0;
  const Eigen::Isometry3d lidar_from_cam = frame.T_cam_lidar.inverse();
#pragma omp parallel for schedule(dynamic, 4)
  for (int y = 0; y < p.height; ++y) {
    for (int x = 0; x < p.width; ++x) {
      const Eigen::Vector3d dir = pixelRay(p, x, y);
      Hit hit;
      if (!scene.intersect(centre, dir, 0.0, std::numeric_limits<double>::infinity(), &hit)) {
        continue;  // sky
      }
      const double z = hit.t * dir.z();
      frame.depth(y, x) = static_cast<float>(z);
      frame.disparity(y, x) = static_cast<float>(p.fx * p.baseline / z);
      if (scene.material(hit.material).low_texture) frame.low_texture(y, x) = 255;
      const Eigen::Vector3d q = lidar_from_cam * (hit.point - centre);
      const double elevation = std::atan2(q.z(), std::hypot(q.x(), q.y()));
      if (elevation >= min_elevation && elevation <= max_elevation) frame.lidar_fov(y, x) = 255;
    }
  }
}

/// Where the noise-free point `world` lands in the left image and whether the camera sees it.
PointTruth pointTruth(const Scene& scene, const SyntheticParams& p, const Eigen::Vector3d& centre,
                      const Eigen::Vector3d& world) {
  PointTruth t;
  const Eigen::Vector3d c = world - centre;
  t.depth = static_cast<float>(c.z());
  if (!(c.z() > 0.0)) return t;
  const double u = p.fx * c.x() / c.z() + p.cx, v = p.fy * c.y() / c.z() + p.cy;
  const auto ui = static_cast<int>(std::floor(u + 0.5)), vi = static_cast<int>(std::floor(v + 0.5));
  if (ui < 0 || ui >= p.width || vi < 0 || vi >= p.height) return t;
  t.u = ui;
  t.v = vi;
  t.in_image = true;
  // The point lies on a surface: only a hit clearly before it (1 mm) counts as an occluder.
  t.visible = !scene.segmentBlocked(centre, world, 1e-3);
  return t;
}

}  // namespace

void SyntheticParams::validate() const {
  require(width >= 16 && height >= 16, "image must be at least 16x16 px");
  require(fx > 0 && fy > 0, "fx and fy must be > 0 [px]");
  require(std::isfinite(cx) && std::isfinite(cy), "cx and cy must be finite [px]");
  require(baseline > 0, "baseline must be > 0 [m]");
  require(subsamples >= 1 && subsamples <= 8, "subsamples must be in [1, 8]");
  require(image_noise_sigma >= 0, "image_noise_sigma must be >= 0");
  require(gamma > 0, "gamma must be > 0");
  require(rings == 64 || rings == 128, "rings must be 64 or 128, got " + std::to_string(rings));
  require(azimuth_step_deg >= 0 && azimuth_step_deg <= 10, "azimuth_step_deg must be in [0, 10]");
  require(range_noise_sigma >= 0, "range_noise_sigma must be >= 0 [m]");
  require(dropout_probability >= 0 && dropout_probability < 1,
          "dropout_probability must be in [0, 1)");
  require(lidar_position.allFinite(), "lidar_position must be finite");
  require(speed >= 0 && std::isfinite(speed), "speed must be >= 0 [m/s]");
  require(frame_period > 0, "frame_period must be > 0 [s]");
  require(camera_height > 0, "camera_height must be > 0 [m]");
  require(std::isfinite(lidar_time_offset) && std::abs(lidar_time_offset) <= frame_period,
          "lidar_time_offset must be within one frame_period of the image instant [s]");
}

SyntheticParams SyntheticParams::resized(int new_width, int new_height) const {
  SyntheticParams p = *this;
  const double sx = static_cast<double>(new_width) / width;
  const double sy = static_cast<double>(new_height) / height;
  p.width = new_width;
  p.height = new_height;
  p.fx = fx * sx;
  p.fy = fy * sy;
  p.cx = (cx + 0.5) * sx - 0.5;  // pixel centres are at integer coordinates
  p.cy = (cy + 0.5) * sy - 0.5;
  return p;
}

StereoCamera SyntheticParams::camera() const {
  StereoCamera c;
  c.fx = fx;
  c.fy = fy;
  c.cx = cx;
  c.cy = cy;
  c.baseline = baseline;
  c.width = width;
  c.height = height;
  return c;
}

Eigen::Isometry3d SyntheticParams::cameraFromLidar() const {
  Eigen::Matrix3d r;  // columns: the LiDAR's x (forward), y (left), z (up) in optical axes
  r << 0, -1, 0,      //
      0, 0, -1,       //
      1, 0, 0;
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = r;
  t.translation() = lidar_position;
  return t;
}

Eigen::Isometry3d SyntheticParams::worldFromCamera(double t) const {
  return Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, speed * t));
}

LidarModel SyntheticParams::lidarModel() const {
  LidarModel model = LidarModel::forRings(rings);
  if (azimuth_step_deg > 0.0) model.azimuth_step_deg = azimuth_step_deg;
  model.sweep_period = frame_period;
  return model;
}

SyntheticFrame renderFrame(const Scene& scene, const SyntheticParams& params, int index) {
  params.validate();
  if (index < 0) throw std::invalid_argument("sim::renderFrame: frame index must be >= 0");
  SyntheticFrame frame;
  frame.camera = params.camera();
  frame.T_cam_lidar = params.cameraFromLidar();
  frame.stamp = index * params.frame_period;
  frame.cloud_stamp = frame.stamp;
  frame.T_world_cam = params.worldFromCamera(frame.stamp);
  const Eigen::Vector3d left_centre = frame.T_world_cam.translation();
  const Eigen::Vector3d right_centre = left_centre + Eigen::Vector3d(params.baseline, 0.0, 0.0);

  const uint64_t frame_seed = hashCombine(params.seed, static_cast<uint64_t>(index));
  frame.left = renderView(scene, params, left_centre, left_centre, hashCombine(frame_seed, 0x1ef7));
  frame.right =
      renderView(scene, params, right_centre, left_centre, hashCombine(frame_seed, 0x7197));
  renderGroundTruth(scene, params, left_centre, frame);

  LidarNoise noise;
  noise.range_sigma_m = params.range_noise_sigma;
  noise.dropout_probability = params.dropout_probability;
  noise.seed = hashCombine(frame_seed, 0x11da7);
  SimulatedSweep sweep;
  if (params.moving_sweep) {
    const double period = params.frame_period;
    frame.cloud_stamp = frame.stamp + params.lidar_time_offset + 0.5 * period;
    const std::function<Eigen::Isometry3d(double)> pose_at = [&](double t) {
      return params.worldFromCamera(frame.cloud_stamp + t) * frame.T_cam_lidar;
    };
    sweep = simulateMovingSweep(scene, params.lidarModel(), pose_at, -0.5 * period, noise);
  } else {
    sweep = simulateSweep(scene, params.lidarModel(), frame.T_world_cam * frame.T_cam_lidar, noise);
  }
  frame.cloud = sweep.cloud;
  frame.truth.resize(sweep.true_points.size());
#pragma omp parallel for schedule(dynamic, 256)
  for (int i = 0; i < static_cast<int>(sweep.true_points.size()); ++i) {
    frame.truth[i] = pointTruth(scene, params, left_centre, sweep.true_points[i]);
  }
  return frame;
}

SyntheticFrame generateStreetFrame(const SyntheticParams& params, int index) {
  params.validate();
  StreetLayout layout;
  layout.camera_height = params.camera_height;
  layout.seed = params.seed;
  return renderFrame(makeStreetScene(layout), params, index);
}

}  // namespace sim
}  // namespace lidar_stereo_fusion
