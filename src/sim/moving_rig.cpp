#include "lidar_stereo_fusion/sim/moving_rig.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/core/metrics.h"

namespace lidar_stereo_fusion {
namespace sim {

namespace {

/// Disparity scores over the LiDAR's field of view (ground truth elsewhere set to none).
DisparityMetrics scoreInFov(const cv::Mat1f& disparity, const SyntheticFrame& frame) {
  cv::Mat1f reference = frame.disparity.clone();
  reference.setTo(0.f, frame.lidar_fov == 0);
  return evaluateDisparity(fillLikeDevkit(disparity, MapKind::kDisparity), reference);
}

/// MAE [px] of the projected points alone, over the pixels they land on inside the field of view.
double sparseMae(const SparseDisparity& sparse, const SyntheticFrame& frame) {
  double sum = 0;
  int count = 0;
  for (int v = 0; v < sparse.disparity.rows; ++v) {
    for (int u = 0; u < sparse.disparity.cols; ++u) {
      const float d = sparse.disparity(v, u), ref = frame.disparity(v, u);
      if (d > 0.f && ref > 0.f && frame.lidar_fov(v, u)) {
        sum += std::abs(d - ref);
        ++count;
      }
    }
  }
  return count > 0 ? sum / count : 0.0;
}

}  // namespace

SweepMotion frameMotion(const SyntheticFrame& frame, const SyntheticParams& params, int samples) {
  // The rig drives along the street's +z, the left optical axis: in the LiDAR frame that is
  // T_cam_lidar's rotation transposed applied to (0, 0, speed).
  const Eigen::Vector3d velocity =
      frame.T_cam_lidar.linear().transpose() * Eigen::Vector3d(0.0, 0.0, params.speed);
  const auto [first, last] = timeSpan(frame.cloud);
  return constantVelocityMotion(velocity, Eigen::Vector3d::Zero(), frame.stamp - frame.cloud_stamp,
                                sampleTimes(first, last, samples));
}

std::vector<MovingRigRow> runMovingRig(
    const SyntheticParams& base, const std::vector<double>& speeds,
    const std::vector<double>& offsets,
    const std::vector<std::pair<std::string, FusionParams>>& methods, int frames) {
  std::vector<MovingRigRow> rows;
  // Rows are added at the first frame and accumulated (then divided) over the others.
  size_t row = 0;
  int frame_index = 1;
  const auto score = [&](const SyntheticFrame& frame, const LidarCloud& cloud, double speed,
                         double offset, const std::string& sweep) {
    FusionInput input;
    input.left = frame.left;
    input.right = frame.right;
    input.cloud = cloud;
    input.T_cam_lidar = frame.T_cam_lidar;
    input.camera = frame.camera;
    for (const auto& [name, params] : methods) {
      FusionPipeline pipeline(params);
      const FusionResult result = pipeline.process(input);
      const DisparityMetrics m = scoreInFov(result.disparity, frame);
      const double w = 1.0 / frames;
      if (frame_index == 1) rows.push_back({name, speed, offset, sweep, 0.0, 0.0, 0.0});
      rows[row].mae_px += w * m.mae_px;
      rows[row].bad3 += w * m.bad3;
      rows[row].prior_mae_px += w * sparseMae(result.sparse, frame);
      ++row;
    }
  };
  for (frame_index = 1; frame_index <= frames; ++frame_index) {
    row = 0;
    for (const double speed : speeds) {
      SyntheticParams p = base;
      p.speed = speed;
      p.moving_sweep = false;
      const SyntheticFrame still = generateStreetFrame(p, frame_index);
      score(still, still.cloud, speed, 0.0, "still");
      for (const double offset : offsets) {
        p.moving_sweep = true;
        p.lidar_time_offset = offset;
        const SyntheticFrame frame = generateStreetFrame(p, frame_index);
        score(frame, frame.cloud, speed, offset, "as taken");
        LidarCloud compensated = frame.cloud;
        compensateMotion(compensated, frameMotion(frame, p));
        removePointsHiddenBeside(compensated, frame.T_cam_lidar, frame.camera);
        score(frame, compensated, speed, offset, "compensated");
      }
    }
  }
  return rows;
}

std::string formatMovingRig(const std::vector<MovingRigRow>& rows) {
  std::ostringstream out;
  out << "| method | speed [m/s] | LiDAR offset [ms] | sweep | MAE in LiDAR view [px] | "
         "> 3 px | projected points' MAE [px] |\n|---|---|---|---|---|---|---|\n";
  out << std::fixed;
  for (const MovingRigRow& r : rows) {
    out << "| " << r.method << " | " << std::setprecision(0) << r.speed << " | "
        << (r.sweep == "still" ? std::string("-") : std::to_string(std::lround(r.offset * 1e3)))
        << " | " << r.sweep << " | " << std::setprecision(3) << r.mae_px << " | "
        << std::setprecision(2) << 100.0 * r.bad3 << " % | " << std::setprecision(3)
        << r.prior_mae_px << " |\n";
  }
  return out.str();
}

}  // namespace sim
}  // namespace lidar_stereo_fusion
