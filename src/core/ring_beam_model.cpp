// The beam model of ring recovery (core/ring_recovery.h): every beam of a spinning LiDAR is a line
// t = a + h s in the plane (s, t) = (1 / r, z / r), with a = tan(theta_i) and h = h_i the height
// of its origin. Found layer by layer: the offset h that makes u = t - h s sharpest brings every
// beam with about that offset to one peak of the histogram of u (the HDL-64E's two blocks are two
// layers); each peak is a line, refined by least squares on its inliers; the points no line
// explains make the next layer. Every point then gets its nearest line.
//
// Why not cv::HoughLines: it votes over all directions on an 8-bit image; here the lines are
// nearly parallel and 0.0002 apart in t, which needs a 1D histogram per offset, not an image. And
// why layers, not one Hough space over (h, a) with a peak per line: a beam whose points all lie at
// one range (a ground ring in front of the car) is a peak at every h, a ridge through that space
// that fills the valleys between its neighbours; one offset per layer has no such ridges.
#include "lidar_stereo_fusion/core/ring_recovery.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "ring_beam_lines.h"

namespace lidar_stereo_fusion {
namespace beam_model {

namespace {

constexpr double kMinRange = 0.1;       // [m] r below this counts as kMinRange (on the axis)
constexpr double kMinHoughRange = 1.0;  // [m] nearer points do not vote (s > 1: steep lines)
constexpr double kMaxHoughTan = 3.0;    // |z / r| above this (72 deg) does not vote
constexpr std::size_t kSample = 16384;  // points that vote (chosen by hash)
constexpr std::size_t kCoarseSample = 2048;
// [m] offsets searched. Beam origins lie within a sensor's housing (HDL-64E: 0.21 m); a wider
// search would find the ground, z = -(sensor height), as one line at h = -height.
constexpr double kMaxOffset = 0.5;
constexpr double kMinProminence = 0.5;  // a peak must fall to half its height on both sides
constexpr int kMaxLayers = 4;           // offsets tried (HDL-64E: 2 blocks)
constexpr double kDoneFraction = 0.01;  // no further layer once fewer sample points are left
// [m] A layer that added no line makes its offset barren: later layers search elsewhere (points
// between established beams, a VoxelGrid's mixes, can make the same offset look sharpest again).
constexpr double kBarrenRadius = 0.02;

/// One level of the offset search: offsets centre +- steps * step, bins of `bin` [tan].
struct SearchLevel {
  int steps;
  double step, bin;
  bool full_sample;
};
// Coarse steps of 0.01 m: the minimum is ~0.02 m wide (a beam spacing over the spread of 1 / r).
constexpr SearchLevel kSearch[] = {
    {static_cast<int>(kMaxOffset / 0.01 + 0.5), 0.01, 1e-3, false},
    {10, 0.001, kBin, true},
};

/// A hash of the point's coordinates: picks samples independently of the point order.
std::uint32_t pointHash(const LidarPoint& p) {
  std::uint32_t x, y, z;
  std::memcpy(&x, &p.x, 4);
  std::memcpy(&y, &p.y, 4);
  std::memcpy(&z, &p.z, 4);
  std::uint32_t h = x * 0x9E3779B1U ^ y * 0x85EBCA77U ^ z * 0xC2B2AE3DU;
  h ^= h >> 15;
  h *= 0x2C1B3C6DU;
  h ^= h >> 12;
  return h;
}

/// About `target` of the points, chosen by their hash (order independent); `shift` picks other
/// bits of the hash for a sample of a sample.
std::vector<LinePoint> hashSample(const std::vector<LinePoint>& points, std::size_t target,
                                  int shift) {
  const std::uint32_t stride =
      static_cast<std::uint32_t>(std::max<std::size_t>(1, (points.size() + target - 1) / target));
  if (stride == 1) return points;
  std::vector<LinePoint> out;
  out.reserve(2 * target);
  for (const LinePoint& q : points) {
    if ((q.hash >> shift) % stride == 0) out.push_back(q);
  }
  return out;
}

/// Histogram of u = t - h s over bins of `width` from `lo`, with buffers reused across offsets.
struct OffsetHistogram {
  double lo = 0.0, width = 0.0;
  std::vector<int> counts;
  std::vector<std::size_t> bins;
  std::size_t occupied = 0;  ///< bins with at least one point

  /// Adds the points at offset h (the range must hold t - h s of every point).
  void fill(const std::vector<LinePoint>& points, double h) {
    bins.resize(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      bins[i] = static_cast<std::size_t>((points[i].t - h * points[i].s - lo) / width);
      occupied += counts[bins[i]]++ == 0 ? 1 : 0;
    }
  }
  void clear() {
    for (const std::size_t b : bins) counts[b] = 0;
    occupied = 0;
  }
};

/// An empty histogram whose range holds t - h s for h in [h_lo, h_hi], two empty bins each end.
OffsetHistogram offsetHistogram(const std::vector<LinePoint>& points, double h_lo, double h_hi,
                                double width) {
  OffsetHistogram out;
  out.width = width;
  if (points.empty()) return out;
  double lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
  for (const LinePoint& q : points) {
    lo = std::min(lo, std::min(q.t - h_lo * q.s, q.t - h_hi * q.s));
    hi = std::max(hi, std::max(q.t - h_lo * q.s, q.t - h_hi * q.s));
  }
  out.lo = lo - 2 * width;
  out.counts.assign(static_cast<std::size_t>((hi - out.lo) / width) + 3, 0);
  return out;
}

/// True when h lies within kBarrenRadius of one of `barren`.
bool nearBarren(double h, const std::vector<double>& barren) {
  return std::any_of(barren.begin(), barren.end(),
                     [h](double b) { return std::abs(h - b) < kBarrenRadius; });
}

/// The offset in centre +- level.steps * level.step that makes t - h s sharpest: fewest occupied
/// bins; ties go to the offset nearest the centre (points all at one range keep it: any offset
/// separates them). Offsets near `barren` ones are skipped. Not the sum of squared counts: that
/// rewards one huge peak, and a flat ground, z = -(sensor height), is the line t = -height * s:
/// at that offset it is one peak and every beam blurred. Fewest occupied bins rewards all beams
/// sharp at once.
double sharpestOffset(const std::vector<LinePoint>& points, double centre, const SearchLevel& level,
                      const std::vector<double>& barren) {
  OffsetHistogram hist = offsetHistogram(points, centre - level.steps * level.step,
                                         centre + level.steps * level.step, level.bin);
  double best_h = centre;
  std::size_t best = std::numeric_limits<std::size_t>::max();
  for (int m = 0; m <= 2 * level.steps; ++m) {
    const double h = centre + (m % 2 == 0 ? 1 : -1) * ((m + 1) / 2) * level.step;  // outwards
    if (nearBarren(h, barren)) continue;
    hist.fill(points, h);
    if (hist.occupied < best) {
      best = hist.occupied;
      best_h = h;
    }
    hist.clear();
  }
  return best_h;
}

/// The common offset of `points`, coarse to fine (kSearch), away from `barren` offsets.
double layerOffset(const std::vector<LinePoint>& points, const std::vector<double>& barren) {
  const std::vector<LinePoint> coarse = hashSample(points, kCoarseSample, 16);
  double h = 0.0;
  for (const SearchLevel& level : kSearch) {
    h = sharpestOffset(level.full_sample ? points : coarse, h, level, barren);
  }
  return h;
}

/// True when, walking from bin b in direction `step`, the votes fall to (1 - kMinProminence) of
/// votes[b] (or the end is reached) before any bin has more votes than b.
bool fallsAway(const std::vector<int>& votes, std::size_t b, int step) {
  const double valley = (1.0 - kMinProminence) * votes[b];
  for (std::ptrdiff_t j = static_cast<std::ptrdiff_t>(b) + step;
       j >= 0 && j < static_cast<std::ptrdiff_t>(votes.size()); j += step) {
    if (votes[j] <= valley) return true;
    if (votes[j] > votes[b]) return false;
  }
  return true;
}

/// The lines of one layer: the prominent peaks of u = t - h s (3-bin sums of at least
/// `min_votes` that fall to half their height on both sides before a higher bin), ascending a.
std::vector<Line> layerLines(const std::vector<LinePoint>& points, double h, int min_votes,
                             int layer) {
  OffsetHistogram hist = offsetHistogram(points, h, h, kBin);
  hist.fill(points, h);
  std::vector<int> votes(hist.counts.size(), 0);
  for (std::size_t b = 1; b + 1 < votes.size(); ++b) {
    votes[b] = hist.counts[b - 1] + hist.counts[b] + hist.counts[b + 1];
  }
  std::vector<Line> lines;
  for (std::size_t b = 1; b + 1 < votes.size(); ++b) {
    const int v = votes[b];
    if (v < min_votes || v <= votes[b - 1] || v < votes[b + 1]) continue;
    if (fallsAway(votes, b, -1) && fallsAway(votes, b, 1)) {
      Line line;
      line.a = hist.lo + (b + 0.5) * kBin;
      line.h = h;
      line.layer = layer;
      lines.push_back(line);
    }
  }
  return lines;
}

}  // namespace

std::vector<LinePoint> linePoints(const LidarCloud& cloud) {
  std::vector<LinePoint> out;
  out.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const LidarPoint& p = cloud[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    const float r = std::max(std::sqrt(p.x * p.x + p.y * p.y), static_cast<float>(kMinRange));
    out.push_back({1.f / r, p.z / r, static_cast<std::uint32_t>(i), pointHash(p)});
  }
  return out;
}

std::vector<LinePoint> houghSample(const std::vector<LinePoint>& points) {
  const std::uint32_t stride =
      static_cast<std::uint32_t>(std::max<std::size_t>(1, (points.size() + kSample - 1) / kSample));
  std::vector<LinePoint> out;
  out.reserve(std::min(points.size(), 2 * kSample));
  for (const LinePoint& q : points) {
    if (q.s <= 1.0 / kMinHoughRange && std::abs(q.t) <= kMaxHoughTan && q.hash % stride == 0) {
      out.push_back(q);
    }
  }
  return out;
}

std::vector<Line> findLines(const std::vector<LinePoint>& sample) {
  const std::size_t min_votes = std::max<std::size_t>(3, sample.size() / 2000);
  std::vector<Line> lines;
  std::vector<double> barren;
  std::vector<LinePoint> left = sample;
  for (int layer = 0; layer < kMaxLayers; ++layer) {
    if (left.size() < std::max<double>(min_votes, kDoneFraction * sample.size())) break;
    const double h = layerOffset(left, barren);
    const std::vector<Line> found = layerLines(left, h, static_cast<int>(min_votes), layer);
    if (found.empty()) break;
    lines.insert(lines.end(), found.begin(), found.end());
    std::sort(lines.begin(), lines.end(),
              [](const Line& x, const Line& y) { return x.a < y.a || (x.a == y.a && x.h < y.h); });
    lines = refineLines(sample, std::move(lines), layer);
    if (std::none_of(lines.begin(), lines.end(), [&](const Line& l) { return l.layer == layer; })) {
      barren.push_back(h);
    }
    left = unexplained(sample, lines);
  }
  return lines;
}

namespace {

/// Gives every finite point its nearest line as ring and fills the beams and `explained`.
void writeRings(const std::vector<LinePoint>& points, const std::vector<Line>& lines,
                LidarCloud& cloud, BeamModel& out) {
  const LineSet set(lines);
  std::vector<std::uint32_t> nearest;
  nearestLines(points, set, nearest);
  out.beams.assign(lines.size(), BeamLine());
  std::vector<double> squares(lines.size(), 0.0);
  std::vector<int> inliers(lines.size(), 0);
  std::size_t explained = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::uint32_t j = nearest[i];
    cloud[points[i].index].ring = static_cast<int>(j);
    ++out.beams[j].points;
    const double residual = std::abs(set.residual(j, points[i]));
    if (residual < kInlierGate * set.spacing[j]) {
      squares[j] += residual * residual;
      ++inliers[j];
    }
    if (residual < kExplainedGate * set.spacing[j]) ++explained;
  }
  for (std::size_t j = 0; j < lines.size(); ++j) {
    out.beams[j].tan_elevation = lines[j].a;
    out.beams[j].offset = lines[j].h;
    out.beams[j].rms = inliers[j] > 0 ? std::sqrt(squares[j] / inliers[j]) : 0.0;
  }
  out.explained = points.empty() ? 0.0 : static_cast<double>(explained) / points.size();
}

std::string percent(double fraction) {
  return std::to_string(static_cast<int>(std::floor(100.0 * fraction))) + " %";
}

}  // namespace
}  // namespace beam_model

BeamModel recoverRingsByBeamModel(LidarCloud& cloud, int max_beams) {
  if (max_beams < 1) {
    throw std::invalid_argument("recoverRingsByBeamModel: max_beams must be >= 1, got " +
                                std::to_string(max_beams));
  }
  if (cloud.size() > std::numeric_limits<std::uint32_t>::max()) {
    throw std::invalid_argument("recoverRingsByBeamModel: more than 2^32 points");
  }
  for (LidarPoint& p : cloud) p.ring = -1;
  BeamModel out;
  const std::vector<beam_model::LinePoint> points = beam_model::linePoints(cloud);
  const std::vector<beam_model::Line> lines =
      beam_model::findLines(beam_model::houghSample(points));
  if (!lines.empty()) beam_model::writeRings(points, lines, cloud, out);
  const int beams = static_cast<int>(out.beams.size());
  if (beams == 0) {
    out.problem = "no beam lines in " + std::to_string(points.size()) + " points";
  } else if (out.explained < kMinBeamModelExplained) {
    out.problem =
        "the beam lines explain only " + beam_model::percent(out.explained) + " of the points";
  } else if (beams == 1) {
    out.problem = "1 beam line for " + std::to_string(points.size()) + " points";
  } else if (beams > max_beams) {
    out.problem = std::to_string(beams) + " beam lines, more than " + std::to_string(max_beams);
  }
  return out;
}

}  // namespace lidar_stereo_fusion
