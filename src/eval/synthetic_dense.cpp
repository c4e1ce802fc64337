// The dense-LiDAR protocol on the synthetic street: exact depth against a LiDAR-made reference.
#include "lidar_stereo_fusion/eval/synthetic_dense.h"

#include <algorithm>
#include <cmath>
#include <ostream>
#include <stdexcept>

#include "accuracy_common.h"
#include "lidar_stereo_fusion/sim/lidar_model.h"
#include "lidar_stereo_fusion/sim/street_scene.h"

namespace lidar_stereo_fusion {

void SyntheticDenseParams::validate() const {
  if (seeds.empty()) throw std::invalid_argument("SyntheticDenseParams: no seed");
  if (half_span < 0) throw std::invalid_argument("SyntheticDenseParams: half_span < 0");
  if (frame - half_span < 0) {
    throw std::invalid_argument("SyntheticDenseParams: frame - half_span < 0 (frames start at 0)");
  }
  if (footprint_px < 0) throw std::invalid_argument("SyntheticDenseParams: footprint_px < 0");
}

cv::Mat1f syntheticLidarReference(const sim::Scene& scene, const sim::SyntheticParams& params,
                                  int target, int half_span, int footprint_px) {
  params.validate();
  const StereoCamera camera = params.camera();
  const Eigen::Isometry3d T_cam_lidar = params.cameraFromLidar();
  const Eigen::Isometry3d T_target_world =
      params.worldFromCamera(target * params.frame_period).inverse();
  cv::Mat1f reference(params.height, params.width, 0.f);
  for (int k = target - half_span; k <= target + half_span; ++k) {
    const Eigen::Isometry3d T_world_lidar =
        params.worldFromCamera(k * params.frame_period) * T_cam_lidar;
    const sim::SimulatedSweep sweep =
        sim::simulateSweep(scene, params.lidarModel(), T_world_lidar, sim::LidarNoise());
    const Eigen::Isometry3d T_target_lidar = T_target_world * T_world_lidar;
    for (const LidarPoint& p : sweep.cloud) {
      const Eigen::Vector3d c = T_target_lidar * Eigen::Vector3d(p.x, p.y, p.z);
      if (!(c.z() > 0.0)) continue;
      const int v = static_cast<int>(std::floor(camera.fy * c.y() / c.z() + camera.cy + 0.5));
      const int u = static_cast<int>(std::floor(camera.fx * c.x() / c.z() + camera.cx + 0.5));
      if (v < 0 || v >= reference.rows) continue;
      const float z = static_cast<float>(c.z());
      for (int x = std::max(0, u - footprint_px);
           x <= std::min(reference.cols - 1, u + footprint_px); ++x) {
        float& r = reference(v, x);
        if (r == 0.f || z < r) r = z;
      }
    }
  }
  return reference;
}

std::vector<LayoutScores<DepthMetrics>> runSyntheticDenseProtocol(
    const AccuracyOptions& options, const SyntheticDenseParams& params) {
  using namespace accuracy_detail;
  options.validate();
  params.validate();
  std::vector<LayoutScores<DepthMetrics>> out;
  for (const std::string& l : syntheticLayoutNames()) {
    if (wantedLayout(options, l)) out.emplace_back().name = l;
  }
  if (out.empty()) return out;
  const auto rows = pipelineRows(options, options.kitti_pms);
  std::vector<LayoutAccumulator<DepthMetrics>> acc(out.size());
  for (const uint64_t seed : params.seeds) {
    if (options.progress) *options.progress << "synthetic street, seed " << seed << std::endl;
    sim::SyntheticParams sp;
    sp.seed = seed;
    sim::StreetLayout layout;
    layout.camera_height = sp.camera_height;
    layout.seed = seed;
    const sim::Scene scene = sim::makeStreetScene(layout);
    const sim::SyntheticFrame f = sim::renderFrame(scene, sp, params.frame);
    const cv::Mat1f lidar_made =
        syntheticLidarReference(scene, sp, params.frame, params.half_span, params.footprint_px);
    cv::Mat1f exact(f.depth.size(), 0.f);  // the same pixels: only the values differ
    f.depth.copyTo(exact, lidar_made > 0.f);
    kitti::FrameData frame;
    frame.left = f.left;
    frame.right = f.right;
    frame.cloud = f.cloud;
    kitti::Calibration calib;
    calib.camera = f.camera;
    calib.T_cam_velo = f.T_cam_lidar;
    const int rings = distinctRings(f.cloud);
    std::vector<DepthTarget> targets;
    for (size_t i = 0; i < out.size(); ++i) {
      const std::string& name = out[i].name;
      // syn_image: every pixel with a surface (f.depth is 0 on the sky), above the LiDAR too.
      targets.push_back({name == "syn_exact"   ? exact
                         : name == "syn_lidar" ? lidar_made
                                               : f.depth,
                         acc[i], name});
      out[i].items.push_back("seed " + std::to_string(seed));
      out[i].fed_rings.push_back(rings);
    }
    PmsRun pms;
    scoreDepthCaseAgainst({frame, frame.cloud, exact, calib, "", "seed " + std::to_string(seed)},
                          targets, options, rows, pms);
  }
  const std::string what =
      "the synthetic street (seeds " + std::to_string(params.seeds.front()) +
      (params.seeds.size() > 1 ? "-" + std::to_string(params.seeds.back()) : std::string()) +
      "), frame " + std::to_string(params.frame) + ", the full 64-ring sweep fed, scored against ";
  for (size_t i = 0; i < out.size(); ++i) {
    out[i].methods = acc[i].finish();
    if (out[i].name == "syn_exact") {
      out[i].description = what + "the exact depth at the pixels of syn_lidar's reference";
    } else if (out[i].name == "syn_image") {
      out[i].description = what +
                           "the exact depth at every pixel with a surface (not the sky), above "
                           "the LiDAR's view too, where the images alone decide";
    } else {
      out[i].description =
          what + "a reference made of LiDAR returns like KITTI's: the sweeps of frames " +
          std::to_string(params.frame - params.half_span) + "-" +
          std::to_string(params.frame + params.half_span) +
          " from their exact poses, the nearest point per pixel, each return widened by " +
          std::to_string(params.footprint_px) + " px either side (beam footprint)";
    }
  }
  return out;
}

}  // namespace lidar_stereo_fusion
