// One frame of the synthetic street with exact ground truth: a rectified stereo pair rendered by
// ray casting, a LiDAR sweep from a mount offset from the left camera, dense ground-truth depth
// and disparity, and per LiDAR point whether the left camera can see it.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/types.h"
#include "lidar_stereo_fusion/sim/lidar_model.h"
#include "lidar_stereo_fusion/sim/scene.h"

namespace lidar_stereo_fusion {
namespace sim {

/// Everything that defines a synthetic frame besides the scene. Defaults: KITTI-like.
struct SyntheticParams {
  uint64_t seed = 1;  ///< scene layout jitter, textures and all noise

  // Rectified stereo pair (KITTI 2011_09_26 rectified intrinsics).
  int width = 1242;                ///< [px]
  int height = 375;                ///< [px]
  double fx = 721.5377;            ///< [px]
  double fy = 721.5377;            ///< [px]
  double cx = 609.5593;            ///< [px]
  double cy = 172.854;             ///< [px]
  double baseline = 0.54;          ///< right camera is at +baseline along the left camera's x [m]
  int subsamples = 2;              ///< anti-aliasing: subsamples^2 rays per pixel
  double image_noise_sigma = 1.0;  ///< Gaussian noise per channel [grey levels of 255]
  double gamma = 1.8;              ///< display gamma applied to the linear radiance

  // LiDAR.
  int rings = 64;                    ///< 64 (HDL-64E-like) or 128 (VLS-128-like)
  double azimuth_step_deg = 0.0;     ///< 0 = the sensor's own (0.09 for 64 rings, 0.2 for 128)
  double range_noise_sigma = 0.0;    ///< [m]
  double dropout_probability = 0.0;  ///< in [0, 1)
  /// LiDAR origin in the left optical frame [m] (KITTI-like: 0.27 m behind, 0.08 m above). The
  /// LiDAR axes are Velodyne's (x forward, y left, z up), aligned with the camera's.
  Eigen::Vector3d lidar_position{0.0, -0.08, -0.27};

  // Motion: the rig drives along the street's +z.
  double speed = 10.0;          ///< [m/s]
  double frame_period = 0.1;    ///< [s] between frames (one LiDAR revolution)
  double camera_height = 1.65;  ///< above the street's ground [m]
  /// The LiDAR moves during its sweep: each firing is cast from the rig's pose at its own time, and
  /// the LiDAR spins clockwise as a Velodyne does (sim::simulateMovingSweep). false: the whole
  /// sweep is cast from the image instant's pose (a rig standing still, or a motion-compensated
  /// sweep).
  bool moving_sweep = false;
  /// [s] with moving_sweep: the LiDAR faces straight ahead this long after the image instant (0:
  /// the camera is triggered by the LiDAR, as KITTI's; a free-running ZED is up to a period away).
  double lidar_time_offset = 0.0;

  /// Throws std::invalid_argument naming the first impossible value.
  void validate() const;
  /// The same field of view at another image size (intrinsics scaled, pixel centres kept).
  SyntheticParams resized(int new_width, int new_height) const;
  /// The rectified stereo camera.
  StereoCamera camera() const;
  /// LiDAR frame -> left optical frame.
  Eigen::Isometry3d cameraFromLidar() const;
  /// Left optical frame at time `t` [s] (frame k's image instant is k * frame_period) -> street
  /// frame: the rig drives along the street's +z at `speed`.
  Eigen::Isometry3d worldFromCamera(double t) const;
  /// The LiDAR model with this frame's ring count and azimuth step.
  LidarModel lidarModel() const;
};

/// Ground truth of one LiDAR point (for the noise-free surface point its beam hit).
struct PointTruth {
  float depth = 0.f;      ///< z in the left optical frame [m] (<= 0: behind the camera)
  int u = -1, v = -1;     ///< nearest pixel in the left image (i = floor(x + 0.5)), -1 if outside
  bool in_image = false;  ///< depth > 0 and (u, v) inside the left image
  bool visible = false;   ///< in_image and the segment from the left optical centre is unobstructed
};

/// One synthetic frame.
struct SyntheticFrame {
  cv::Mat left, right;            ///< BGR CV_8UC3 rectified images
  LidarCloud cloud;               ///< the sweep in the LiDAR frame (ring, intensity, time)
  std::vector<PointTruth> truth;  ///< one per cloud point
  StereoCamera camera;
  Eigen::Isometry3d T_cam_lidar = Eigen::Isometry3d::Identity();  ///< LiDAR -> left optical
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();  ///< left optical -> street
  cv::Mat1f depth;        ///< exact left depth at pixel centres [m], 0 = sky
  cv::Mat1f disparity;    ///< fx * B / depth [px], 0 = sky
  cv::Mat1b low_texture;  ///< 255 where the pixel centre sees the untextured material
  /// 255 where the surface point at the pixel centre lies within the LiDAR's elevation range as
  /// seen from the LiDAR (ignoring occlusion): where KITTI's accumulated-LiDAR ground truth exists.
  cv::Mat1b lidar_fov;
  double stamp = 0.0;  ///< [s] since the first frame: the image instant
  /// [s] the sweep's stamp, same base: the image instant for a static sweep; with moving_sweep the
  /// sweep's end (velodyne_driver's convention), image instant + lidar_time_offset + period / 2.
  /// Point times are relative to it.
  double cloud_stamp = 0.0;
};

/// Renders frame `index` of `scene`: the left camera at (0, 0, speed * frame_period * index) of
/// the street frame, axes aligned with it; the right camera `baseline` to its right.
SyntheticFrame renderFrame(const Scene& scene, const SyntheticParams& params, int index = 0);

/// Frame `index` of the street scene built from params.seed and params.camera_height.
SyntheticFrame generateStreetFrame(const SyntheticParams& params, int index = 0);

}  // namespace sim
}  // namespace lidar_stereo_fusion
