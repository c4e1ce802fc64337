// Ring hold-out: every keep_every-th ring in, the other rings as the reference depth.
#include "lidar_stereo_fusion/eval/holdout.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace lidar_stereo_fusion {

RingSplit splitRings(const LidarCloud& cloud, int keep_every) {
  if (keep_every < 2) {
    throw std::invalid_argument("splitRings: keep_every must be >= 2, got " +
                                std::to_string(keep_every));
  }
  RingSplit split;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const LidarPoint& p = cloud[i];
    if (p.ring < 0) {
      throw std::invalid_argument("splitRings: point " + std::to_string(i) +
                                  " has no ring; recover rings first");
    }
    (p.ring % keep_every == 0 ? split.fed : split.held_out).push_back(p);
  }
  return split;
}

RingSplit splitRingsEvenOdd(const LidarCloud& cloud) { return splitRings(cloud, 2); }

cv::Mat1f projectReferenceDepth(const LidarCloud& held_out, const Eigen::Isometry3d& T_cam_lidar,
                                const StereoCamera& camera, const ProjectionParams& params) {
  camera.validate();
  params.validate();
  cv::Mat1f depth(camera.height, camera.width, 0.f);
  for (const LidarPoint& point : held_out) {
    const Eigen::Vector3d p = T_cam_lidar * Eigen::Vector3d(point.x, point.y, point.z);
    if (!p.allFinite() || p.z() < params.min_depth || p.z() > params.max_depth) continue;
    // Same pixel rule as projectCloud: pixel i covers [i - 0.5, i + 0.5).
    const double u = std::floor(camera.fx * p.x() / p.z() + camera.cx + 0.5);
    const double v = std::floor(camera.fy * p.y() / p.z() + camera.cy + 0.5);
    if (u < 0 || v < 0 || u >= camera.width || v >= camera.height) continue;
    float& z = depth(static_cast<int>(v), static_cast<int>(u));
    if (z == 0.f || p.z() < z) z = static_cast<float>(p.z());
  }
  return depth;
}

HoldoutCase makeRingHoldout(const LidarCloud& cloud, const Eigen::Isometry3d& T_cam_lidar,
                            const StereoCamera& camera, const ProjectionParams& params,
                            int keep_every) {
  RingSplit split = splitRings(cloud, keep_every);
  HoldoutCase holdout;
  holdout.reference_depth = projectReferenceDepth(split.held_out, T_cam_lidar, camera, params);
  if (cv::countNonZero(holdout.reference_depth) == 0) {
    throw std::invalid_argument("makeRingHoldout: no held-out point (ring % " +
                                std::to_string(keep_every) + " != 0) lands in the image");
  }
  holdout.fed = std::move(split.fed);
  return holdout;
}

}  // namespace lidar_stereo_fusion
