// Scan-line (ring) recovery: ring field, sweep order, elevation, and the checks that choose between
// them (ensureRings). The beam model is in ring_beam_model.cpp.
#include "lidar_stereo_fusion/core/ring_recovery.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace lidar_stereo_fusion {

namespace {

constexpr double kPi = 3.14159265358979323846;

inline bool isFinite(const LidarPoint& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

}  // namespace

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

int recoverRingsByElevationBands(LidarCloud& cloud, int bands) {
  if (bands < 1) {
    throw std::invalid_argument("recoverRingsByElevationBands: bands must be >= 1, got " +
                                std::to_string(bands));
  }
  std::vector<std::pair<double, std::size_t>> order;  // (elevation [rad], index)
  order.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    LidarPoint& p = cloud[i];
    p.ring = -1;
    if (isFinite(p)) order.emplace_back(std::atan2(p.z, std::hypot(p.x, p.y)), i);
  }
  std::sort(order.begin(), order.end());
  const std::size_t n = order.size();
  const std::size_t used = std::min(n, static_cast<std::size_t>(bands));
  for (std::size_t k = 0; k < n; ++k) {
    cloud[order[k].second].ring = static_cast<int>(k * used / n);
  }
  return static_cast<int>(used);
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
    case RingSource::kBeamModel:
      return "beam_model";
    case RingSource::kElevation:
      break;
  }
  return "elevation";
}

int countRings(const LidarCloud& cloud) {
  int max_ring = -1;
  for (const LidarPoint& p : cloud) max_ring = std::max(max_ring, p.ring);
  return max_ring + 1;
}

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

namespace {

/// Appends "method: problem" to the fallbacks of `out`.
void note(RingRecovery& out, const std::string& method, const std::string& problem) {
  out.fallbacks += (out.fallbacks.empty() ? "" : "; ") + method + ": " + problem;
}

/// Fraction of the finite points whose azimuth steps back by more than 0.1 deg from the previous
/// point of their ring, not counting the +-180 deg wrap. In sweep order a laser's azimuth only
/// rises (KITTI: never back by more than 0.01 deg); a cloud that keeps most of a sweep's order but
/// not all of it (the points in view sorted by image row, the rest as stored) gets
/// plausible-looking rings from the sweep order rule, with one of them holding every point in view.
double backwardStepFraction(const LidarCloud& cloud) {
  constexpr double kMaxBackwardStep = 0.1 * kPi / 180.0;
  std::size_t backward = 0, finite = 0;
  const LidarPoint* previous = nullptr;
  for (const LidarPoint& p : cloud) {
    if (!isFinite(p)) continue;
    ++finite;
    if (previous != nullptr && previous->ring == p.ring) {
      const double step = std::atan2(p.y, p.x) - std::atan2(previous->y, previous->x);
      backward += step < -kMaxBackwardStep && step > -kPi ? 1 : 0;
    }
    previous = &p;
  }
  return finite > 0 ? static_cast<double>(backward) / finite : 0.0;
}

/// Uses the sweep order when it gives plausible rings; else notes why not.
bool trySweepOrder(LidarCloud& cloud, int max_rings, RingRecovery& out) {
  LidarCloud by_order = cloud;
  const int rings = recoverRingsBySweepOrder(by_order);
  std::string problem = rings > max_rings ? std::to_string(rings) + " rings, more than " +
                                                std::to_string(max_rings) + " (not in sweep order)"
                                          : ringPlausibilityProblem(by_order, max_rings);
  const double backward = problem.empty() ? backwardStepFraction(by_order) : 0.0;
  if (backward > 0.01) {
    problem = std::to_string(static_cast<int>(100 * backward)) +
              " % of the points step back in azimuth (not in sweep order)";
  }
  if (!problem.empty()) {
    note(out, "sweep order", problem);
    return false;
  }
  cloud = std::move(by_order);
  out.source = RingSource::kSweepOrder;
  out.rings = rings;
  return true;
}

/// What the beam model gave ensureRings.
enum class BeamOutcome { kUsed, kNoScanLines, kNotUsed };

/// Uses the beam model when it finds plausible rings; else notes why not. Lines that explain
/// fewer than kMinBeamModelExplained of the points but more than kMinScanLineExplained (a
/// VoxelGrid's centroids near the sensor average neighbouring beams; 80-90 % at a 0.1 m leaf on
/// KITTI) are still scan lines, better than any elevation binning: used, flagged implausible.
BeamOutcome tryBeamModel(LidarCloud& cloud, int max_rings, RingRecovery& out) {
  LidarCloud by_beams = cloud;
  const BeamModel model = recoverRingsByBeamModel(by_beams, max_rings);
  const int beams = static_cast<int>(model.beams.size());
  const std::string rings_problem =
      beams >= 2 && beams <= max_rings ? ringPlausibilityProblem(by_beams, max_rings) : "";
  const std::string problem = model.problem.empty() ? rings_problem : model.problem;
  if (!problem.empty()) note(out, "beam model", problem);
  const bool partial = model.explained >= kMinScanLineExplained && beams >= 2 &&
                       beams <= max_rings && rings_problem.empty();
  if (!problem.empty() && !partial) {
    return model.explained < kMinScanLineExplained ? BeamOutcome::kNoScanLines
                                                   : BeamOutcome::kNotUsed;
  }
  cloud = std::move(by_beams);
  out.source = RingSource::kBeamModel;
  out.rings = beams;
  out.plausible = problem.empty();
  return BeamOutcome::kUsed;
}

/// Elevation binning (recoverRingsByElevation), flagged when implausible or coarse.
void useElevation(LidarCloud& cloud, int num_rings, int max_rings, RingRecovery& out) {
  out.source = RingSource::kElevation;
  out.rings = recoverRingsByElevation(cloud, num_rings);
  std::string problem = ringPlausibilityProblem(cloud, max_rings);
  std::size_t finite = 0;
  for (const LidarPoint& p : cloud) finite += isFinite(p) ? 1 : 0;
  // Elevation binning that finds far fewer beams than the sensor has merged beams (beam origins
  // that differ and the beam model failed): plausible-looking, but coarse.
  if (problem.empty() && finite >= 100 && 2 * out.rings < num_rings) {
    problem = "only " + std::to_string(out.rings) +
              " of ~num_rings = " + std::to_string(num_rings) + " beams separable by elevation";
  }
  if (!problem.empty()) {
    note(out, "elevation", problem);
    out.plausible = false;
  }
}

}  // namespace

RingRecovery ensureRings(LidarCloud& cloud, bool has_ring_field, int num_rings) {
  if (num_rings < 1) {
    throw std::invalid_argument("ensureRings: num_rings must be >= 1, got " +
                                std::to_string(num_rings));
  }
  const int max_rings =
      std::min(2 * num_rings, static_cast<int>(std::numeric_limits<short>::max()));
  RingRecovery out;
  if (has_ring_field) {
    const std::string problem =
        hasRings(cloud) ? ringPlausibilityProblem(cloud, max_rings) : "points without a valid ring";
    if (problem.empty()) {
      out.source = RingSource::kField;
      out.rings = countRings(cloud);
      return out;
    }
    note(out, "ring field", problem);
  }
  if (trySweepOrder(cloud, max_rings, out)) return out;
  const BeamOutcome beams = tryBeamModel(cloud, max_rings, out);
  if (beams == BeamOutcome::kUsed) return out;
  std::size_t finite = 0;
  for (const LidarPoint& p : cloud) finite += isFinite(p) ? 1 : 0;
  if (beams == BeamOutcome::kNotUsed || finite < 100) {
    useElevation(cloud, num_rings, max_rings, out);
    return out;
  }
  // No scan lines (Livox-like): bands of equal point counts give BI* evenly spaced pseudo lines.
  out.source = RingSource::kElevation;
  out.rings = recoverRingsByElevationBands(cloud, num_rings);
  out.plausible = false;
  note(out, "elevation",
       "no scan lines, " + std::to_string(out.rings) + " bands of equal point counts");
  return out;
}

}  // namespace lidar_stereo_fusion
