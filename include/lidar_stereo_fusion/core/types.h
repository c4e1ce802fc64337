// Basic types shared by every stage of the ROS-free fusion core.
//
// Conventions (see doc/conventions.md):
//  * Images are rectified; the left camera is the reference view.
//  * Disparity is in pixels, d = x_left - x_right = fx * B / z, always > 0 for a valid value.
//    A disparity map stores 0 where there is no value ("empty").
//  * Depth z is in metres along the left camera's optical axis; 0 / NaN marks "no value"
//    (0 in core cv::Mat1f depth maps, NaN in ROS depth images, 0 in KITTI PNGs).
//  * The left camera optical frame is x right, y down, z forward (REP 103 optical).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace lidar_stereo_fusion {

/// Rectified stereo camera: pinhole intrinsics of the left view and the baseline.
struct StereoCamera {
  double fx = 0.0;        ///< focal length along x [px]
  double fy = 0.0;        ///< focal length along y [px]
  double cx = 0.0;        ///< principal point x [px]
  double cy = 0.0;        ///< principal point y [px]
  double baseline = 0.0;  ///< distance between the optical centres [m], > 0
  int width = 0;          ///< image width [px]
  int height = 0;         ///< image height [px]

  /// Disparity [px] of a point at depth z [m] (z > 0).
  double disparityFromDepth(double z) const { return fx * baseline / z; }
  /// Depth [m] of disparity d [px] (d > 0).
  double depthFromDisparity(double d) const { return fx * baseline / d; }
  /// Throws std::invalid_argument naming the first impossible value.
  void validate() const;
};

/// Plausible stereo baselines [m]: from a 1 cm micro rig to a 5 m wide truck rig. A value outside
/// is almost always a unit mistake (a projection matrix written in millimetres gives 1000x).
constexpr double kMinPlausibleBaseline = 0.01;
constexpr double kMaxPlausibleBaseline = 5.0;
/// Empty when `baseline` [m] is in [kMinPlausibleBaseline, kMaxPlausibleBaseline], else a message
/// naming the value, the range and the likely unit mistake with the value it would then be.
std::string baselinePlausibilityProblem(double baseline);

/// One LiDAR return in the LiDAR frame.
struct LidarPoint {
  float x = 0.f, y = 0.f, z = 0.f;  ///< position [m] in the LiDAR frame
  float intensity = 0.f;            ///< reflectance / intensity (sensor units)
  int ring = -1;                    ///< laser (scan line) index, -1 when unknown
  float time = 0.f;                 ///< time offset within the sweep [s] (0 when unknown)
};

using LidarCloud = std::vector<LidarPoint>;

}  // namespace lidar_stereo_fusion
