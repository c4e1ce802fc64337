// Algorithm 1 against exact visibility: which occluded points were removed, which visible kept.
#include "lidar_stereo_fusion/sim/occlusion_truth.h"

#include <cmath>
#include <stdexcept>

namespace lidar_stereo_fusion {
namespace sim {

OcclusionRemovalScore scoreOcclusionRemoval(const SyntheticFrame& frame, const ScanLines& before,
                                            const ScanLines& after) {
  const cv::Size size(frame.camera.width, frame.camera.height);
  if (before.disparity.size() != size || after.disparity.size() != size) {
    throw std::invalid_argument("scoreOcclusionRemoval: scan lines differ from the image size");
  }
  if (frame.truth.size() != frame.cloud.size()) {
    throw std::invalid_argument("scoreOcclusionRemoval: frame has no truth for every point");
  }
  const StereoCamera& cam = frame.camera;
  cv::Mat1b counted(size, uint8_t{0});
  OcclusionRemovalScore score;
  for (size_t i = 0; i < frame.cloud.size(); ++i) {
    if (!frame.truth[i].in_image) continue;
    const LidarPoint& p = frame.cloud[i];
    const Eigen::Vector3d c = frame.T_cam_lidar * Eigen::Vector3d(p.x, p.y, p.z);
    if (!(c.z() > 0.0)) continue;
    // The measured point's pixel and disparity, rounded as projectCloud does.
    const auto u = static_cast<int>(std::floor(cam.fx * c.x() / c.z() + cam.cx + 0.5));
    const auto v = static_cast<int>(std::floor(cam.fy * c.y() / c.z() + cam.cy + 0.5));
    if (u < 0 || u >= size.width || v < 0 || v >= size.height || counted(v, u)) continue;
    const double d = cam.disparityFromDepth(c.z());
    if (std::abs(before.disparity(v, u) - d) > 1e-4 * d) continue;  // lost the z-buffer, or moved
    counted(v, u) = 255;
    const bool still_there = after.disparity(v, u) > 0.f;
    if (frame.truth[i].visible) {
      ++score.visible;
      score.visible_kept += still_there ? 1 : 0;
    } else {
      ++score.occluded;
      score.occluded_removed += still_there ? 0 : 1;
    }
  }
  return score;
}

}  // namespace sim
}  // namespace lidar_stereo_fusion
