// Stage 1: LiDAR projection (paper Eq. 1-2).
#include "lidar_stereo_fusion/core/lidar_projection.h"

#include "lidar_stereo_fusion/core/param_table.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace lidar_stereo_fusion {

namespace {

/// Nearest pixel index of a sub-pixel coordinate: pixel i covers [i - 0.5, i + 0.5) (OpenCV
/// centres). Stays a double so that far-off coordinates are compared before any int conversion.
inline double roundToPixel(double u) { return std::floor(u + 0.5); }

inline bool isFinite(const LidarPoint& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

void validateTransform(const Eigen::Isometry3d& T) {
  if (!T.matrix().allFinite()) {
    throw std::invalid_argument("projectCloud: T_cam_lidar contains NaN or inf");
  }
  const Eigen::Matrix3d R = T.linear();
  const double orthogonality_error = (R * R.transpose() - Eigen::Matrix3d::Identity()).norm();
  if (orthogonality_error > 1e-3 || R.determinant() < 0.0) {
    throw std::invalid_argument(
        "projectCloud: T_cam_lidar rotation is not a proper rotation (|R R^T - I| = " +
        std::to_string(orthogonality_error) + ", det = " + std::to_string(R.determinant()) + ")");
  }
}

/// Ring index as stored in the cv::Mat1s ring map; -1 for unknown.
short ringToShort(int ring) {
  if (ring < 0) return -1;
  if (ring > std::numeric_limits<short>::max()) {
    throw std::invalid_argument("projectCloud: ring index " + std::to_string(ring) +
                                " does not fit the ring map (max " +
                                std::to_string(std::numeric_limits<short>::max()) + ")");
  }
  return static_cast<short>(ring);
}

}  // namespace

void ProjectionParams::validate() const {
  requireRanges("ProjectionParams", *this);
  if (max_depth <= min_depth) {
    throw std::invalid_argument("ProjectionParams: max_depth must be > min_depth (" +
                                formatParamDouble(min_depth) + ") m, got " +
                                formatParamDouble(max_depth));
  }
}

SparseDisparity projectCloud(const LidarCloud& cloud, const Eigen::Isometry3d& T_cam_lidar,
                             const StereoCamera& camera, const ProjectionParams& params,
                             View view) {
  camera.validate();
  params.validate();
  validateTransform(T_cam_lidar);

  SparseDisparity out;
  out.disparity.create(camera.height, camera.width);
  out.disparity.setTo(0.f);
  out.ring.create(camera.height, camera.width);
  out.ring.setTo(-1);

  const Eigen::Matrix3d R = T_cam_lidar.linear();
  const Eigen::Vector3d t = T_cam_lidar.translation();
  const double fxb = camera.fx * camera.baseline;
  const bool right = view == View::kRight;

  for (const LidarPoint& point : cloud) {
    if (!isFinite(point)) {
      ++out.points_not_finite;
      continue;
    }
    const Eigen::Vector3d p = R * Eigen::Vector3d(point.x, point.y, point.z) + t;
    const double z = p.z();
    if (z < params.min_depth || z > params.max_depth) continue;
    ++out.points_in_front;
    const double d = fxb / z;
    const double u_left = camera.fx * p.x() / z + camera.cx;
    const double v = camera.fy * p.y() / z + camera.cy;
    // Right view: the same point seen at x_right = x_left - d (rectified, parallel axes); the
    // sub-pixel x_right is rounded, not round(x_left) - d.
    const double col_f = roundToPixel(right ? u_left - d : u_left);
    const double row_f = roundToPixel(v);
    if (!(col_f >= 0.0 && col_f < camera.width && row_f >= 0.0 && row_f < camera.height)) continue;
    const int col = static_cast<int>(col_f);
    const int row = static_cast<int>(row_f);
    ++out.points_in_image;
    float& stored = out.disparity(row, col);
    const float df = static_cast<float>(d);
    if (df > stored) {  // z-buffer: the nearest point (largest disparity) wins; ties keep the first
      stored = df;
      out.ring(row, col) = ringToShort(point.ring);
    }
  }
  return out;
}

}  // namespace lidar_stereo_fusion
