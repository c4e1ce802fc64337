// Stage 1: LiDAR projection (paper Eq. 1-2) and scan-line (ring) recovery.
#include "lidar_stereo_fusion/core/lidar_projection.h"

#include "lidar_stereo_fusion/core/param_table.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace lidar_stereo_fusion {

namespace {

constexpr double kPi = 3.14159265358979323846;

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

int recoverRingsBySweepOrder(LidarCloud& cloud) {
  // A laser's azimuth rises from just left of straight ahead (small positive), passes the +-180 deg
  // wrap behind the car, and ends just right of straight ahead (small negative). The next laser
  // therefore starts where the azimuth crosses 0 going up. The crossing only counts once the
  // current laser has passed the wrap, so jitter of the azimuth around 0 at a laser's first
  // points cannot start a spurious ring. Non-finite points take the ring of their neighbours.
  int ring = 0;
  bool passed_wrap = false;
  bool have_previous = false;
  double previous = 0.0;
  for (LidarPoint& point : cloud) {
    if (isFinite(point)) {
      const double azimuth = std::atan2(point.y, point.x);
      if (have_previous) {
        if (previous > 0.0 && azimuth < 0.0 && previous - azimuth > kPi) passed_wrap = true;
        if (passed_wrap && previous < 0.0 && azimuth >= 0.0 && azimuth - previous < kPi) {
          ++ring;
          passed_wrap = false;
        }
      }
      previous = azimuth;
      have_previous = true;
    }
    point.ring = ring;
  }
  return cloud.empty() ? 0 : ring + 1;
}

int recoverRingsByElevation(LidarCloud& cloud, int num_rings, double min_gap_deg) {
  if (num_rings < 1) {
    throw std::invalid_argument("recoverRingsByElevation: num_rings must be >= 1, got " +
                                std::to_string(num_rings));
  }
  if (!std::isfinite(min_gap_deg) || min_gap_deg < 0.0) {
    throw std::invalid_argument(
        "recoverRingsByElevation: min_gap_deg must be finite and >= 0, "
        "got " +
        std::to_string(min_gap_deg));
  }
  std::vector<double> elevation(cloud.size(), std::numeric_limits<double>::quiet_NaN());
  std::vector<double> sorted;
  sorted.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const LidarPoint& p = cloud[i];
    if (!isFinite(p)) continue;
    elevation[i] = std::atan2(p.z, std::hypot(p.x, p.y)) * 180.0 / kPi;
    sorted.push_back(elevation[i]);
  }
  if (sorted.empty()) {
    for (LidarPoint& p : cloud) p.ring = -1;
    return 0;
  }
  std::sort(sorted.begin(), sorted.end());

  // Beams are the clusters of the sorted elevations: split at the num_rings - 1 widest gaps, but
  // only at gaps of at least min_gap_deg (a beam's own points are far closer together than that).
  std::vector<std::pair<double, std::size_t>> gaps;  // (width, index of the value above the gap)
  gaps.reserve(sorted.size());
  for (std::size_t i = 1; i < sorted.size(); ++i) {
    const double width = sorted[i] - sorted[i - 1];
    if (width >= min_gap_deg && width > 0.0) gaps.emplace_back(width, i);
  }
  const std::size_t num_cuts = std::min(gaps.size(), static_cast<std::size_t>(num_rings - 1));
  std::partial_sort(gaps.begin(), gaps.begin() + num_cuts, gaps.end(),
                    [](const auto& a, const auto& b) {
                      return a.first > b.first || (a.first == b.first && a.second < b.second);
                    });
  std::vector<double> cuts;  // ascending elevations [deg] separating consecutive beams
  cuts.reserve(num_cuts);
  for (std::size_t k = 0; k < num_cuts; ++k) {
    const std::size_t i = gaps[k].second;
    cuts.push_back(0.5 * (sorted[i - 1] + sorted[i]));
  }
  std::sort(cuts.begin(), cuts.end());

  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (std::isnan(elevation[i])) {
      cloud[i].ring = -1;
      continue;
    }
    cloud[i].ring =
        static_cast<int>(std::upper_bound(cuts.begin(), cuts.end(), elevation[i]) - cuts.begin());
  }
  return static_cast<int>(cuts.size()) + 1;
}

bool hasRings(const LidarCloud& cloud) {
  return std::all_of(cloud.begin(), cloud.end(), [](const LidarPoint& p) { return p.ring >= 0; });
}

std::string ringSourceName(RingSource source) {
  switch (source) {
    case RingSource::kField:
      return "ring_field";
    case RingSource::kSweepOrder:
      return "sweep_order";
    default:
      return "elevation";
  }
}

namespace {

int countRings(const LidarCloud& cloud) {
  int max_ring = -1;
  for (const LidarPoint& p : cloud) max_ring = std::max(max_ring, p.ring);
  return max_ring + 1;
}

}  // namespace

std::string ringPlausibilityProblem(const LidarCloud& cloud, int max_rings) {
  const int rings = countRings(cloud);
  std::size_t with_ring = 0;
  for (const LidarPoint& p : cloud) with_ring += p.ring >= 0 && isFinite(p) ? 1 : 0;
  if (with_ring >= 100 && rings < 2) {
    return std::to_string(rings) + " ring for " + std::to_string(with_ring) + " points";
  }
  if (rings > max_rings) {
    return std::to_string(rings) + " rings, more than " + std::to_string(max_rings);
  }
  if (rings < 2) return {};
  std::vector<std::size_t> count(static_cast<std::size_t>(rings), 0);
  std::vector<double> elevation_sum(static_cast<std::size_t>(rings), 0.0);
  for (const LidarPoint& p : cloud) {
    if (p.ring < 0 || !isFinite(p)) continue;
    ++count[p.ring];
    elevation_sum[p.ring] += std::atan2(p.z, std::hypot(p.x, p.y));
  }
  const auto sparse =
      std::count_if(count.begin(), count.end(), [](std::size_t n) { return n < 5; });
  if (4 * sparse > rings) {
    return std::to_string(sparse) + " of " + std::to_string(rings) +
           " rings have fewer than 5 points";
  }
  int up = 0, down = 0;
  double previous = std::numeric_limits<double>::quiet_NaN();
  for (int r = 0; r < rings; ++r) {
    if (count[r] == 0) continue;
    const double mean = elevation_sum[r] / static_cast<double>(count[r]);
    if (!std::isnan(previous)) (mean > previous ? up : down) += 1;
    previous = mean;
  }
  const int pairs = up + down;
  if (pairs > 0 && 5 * std::max(up, down) < 4 * pairs) {
    return "mean elevation per ring is not monotonic in the ring index (" + std::to_string(up) +
           " steps up, " + std::to_string(down) + " down)";
  }
  return {};
}

RingRecovery ensureRings(LidarCloud& cloud, bool has_ring_field, int num_rings) {
  if (num_rings < 1) {
    throw std::invalid_argument("ensureRings: num_rings must be >= 1, got " +
                                std::to_string(num_rings));
  }
  const int max_rings =
      std::min(2 * num_rings, static_cast<int>(std::numeric_limits<short>::max()));
  RingRecovery out;
  const auto note = [&out](const std::string& method, const std::string& problem) {
    out.fallbacks += (out.fallbacks.empty() ? "" : "; ") + method + ": " + problem;
  };
  if (has_ring_field) {
    if (!hasRings(cloud)) {
      note("ring field", "points without a valid ring");
    } else {
      const std::string problem = ringPlausibilityProblem(cloud, max_rings);
      if (problem.empty()) {
        out.source = RingSource::kField;
        out.rings = countRings(cloud);
        return out;
      }
      note("ring field", problem);
    }
  }
  LidarCloud by_order = cloud;
  const int order_rings = recoverRingsBySweepOrder(by_order);
  const std::string order_problem = order_rings > max_rings
                                        ? std::to_string(order_rings) + " rings, more than " +
                                              std::to_string(max_rings) + " (not in sweep order)"
                                        : ringPlausibilityProblem(by_order, max_rings);
  if (order_problem.empty()) {
    cloud = std::move(by_order);
    out.source = RingSource::kSweepOrder;
    out.rings = order_rings;
    return out;
  }
  note("sweep order", order_problem);
  out.source = RingSource::kElevation;
  out.rings = recoverRingsByElevation(cloud, num_rings);
  std::string problem = ringPlausibilityProblem(cloud, max_rings);
  std::size_t finite = 0;
  for (const LidarPoint& p : cloud) finite += isFinite(p) ? 1 : 0;
  // Elevation binning that finds far fewer beams than the sensor has merged beams (beam origins
  // that differ, as on the HDL-64E): plausible-looking, but coarse.
  if (problem.empty() && finite >= 100 && 2 * out.rings < num_rings) {
    problem = "only " + std::to_string(out.rings) +
              " of ~num_rings = " + std::to_string(num_rings) + " beams separable by elevation";
  }
  if (!problem.empty()) {
    note("elevation", problem);
    out.plausible = false;
  }
  return out;
}

}  // namespace lidar_stereo_fusion
