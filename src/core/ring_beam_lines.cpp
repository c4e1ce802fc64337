// The lines of the beam model: nearest line, least-squares refit, merging (ring_beam_lines.h).
#include "ring_beam_lines.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace lidar_stereo_fusion {
namespace beam_model {

namespace {

constexpr int kRefinements = 2;
constexpr double kMinBeamSeparation = 8.7e-4;  // [tan] 0.05 deg: closer lines are one beam
constexpr double kNearGate = 0.1;              // "near" a line: within this times its inlier gate
constexpr double kMinNearFraction = 0.5;       // a line's inliers near it, at least
constexpr int kMinNear = 3;                    // and at least this many
constexpr double kMaxSpacing = 0.05;  // [tan] ~3 deg: the spacing of a line without neighbours
constexpr std::uint32_t kNoLine = ~0U;
constexpr double kOffsetPrior = 0.02;  // [m] SD of the prior that keeps h near the layer's
constexpr double kLineNoise = 1e-4;    // [tan] typical residual of a beam (KITTI: 3e-5..9e-5)
constexpr std::size_t kBatch = 8;      // points searched side by side in nearestLines

/// Sums of one line's inliers for the least-squares fit.
struct LineSums {
  double n = 0, s = 0, t = 0, ss = 0, st = 0, tt = 0;
  double s_lo = std::numeric_limits<double>::max(), s_hi = 0;
  void add(double si, double ti) {
    n += 1;
    s_lo = std::min(s_lo, si);
    s_hi = std::max(s_hi, si);
    s += si;
    t += ti;
    ss += si * si;
    st += si * ti;
    tt += ti * ti;
  }
};

/// Least-squares line through the sums, with a ridge prior (SD kOffsetPrior) pulling h towards
/// `prior.h`: points that all lie at one range do not determine h, and then keep the layer's.
Line fitLine(const LineSums& sums, const Line& prior, double gate) {
  const double lambda = (kLineNoise / kOffsetPrior) * (kLineNoise / kOffsetPrior);
  const double sxx = sums.ss - sums.s * sums.s / sums.n;
  const double sxy = sums.st - sums.s * sums.t / sums.n;
  Line fit;
  fit.layer = prior.layer;
  fit.h = (sxy + lambda * prior.h) / (sxx + lambda);
  fit.a = (sums.t - fit.h * sums.s) / sums.n;
  fit.s_lo = sums.s_lo;
  fit.s_hi = sums.s_hi;
  fit.inliers = sums.n;
  fit.gate = gate;
  const double squares = sums.tt - 2 * fit.a * sums.t - 2 * fit.h * sums.st +
                         sums.n * fit.a * fit.a + 2 * fit.a * fit.h * sums.s +
                         fit.h * fit.h * sums.ss;
  fit.rms = std::sqrt(std::max(0.0, squares) / sums.n);
  return fit;
}

/// Refits every line on its inliers among `points`. Lines of `layer` left without two inliers, or
/// whose inliers are no line, are dropped; lines of earlier layers stay. Ascending a.
std::vector<Line> refitLines(const std::vector<LinePoint>& points, const std::vector<Line>& lines,
                             int layer) {
  const LineSet set(lines);
  std::vector<std::uint32_t> nearest;
  nearestLines(points, set, nearest);
  std::vector<LineSums> sums(lines.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::uint32_t j = nearest[i];
    if (std::abs(set.residual(j, points[i])) < kInlierGate * set.spacing[j]) {
      sums[j].add(points[i].s, points[i].t);
    } else {
      nearest[i] = kNoLine;
    }
  }
  std::vector<Line> fits(lines.size());
  for (std::size_t j = 0; j < lines.size(); ++j) {
    if (sums[j].n >= 2) fits[j] = fitLine(sums[j], lines[j], kInlierGate * set.spacing[j]);
  }
  // A line's inliers must gather near the fitted line: more than half within a tenth of the
  // gate. Inliers spread evenly over the gate (a blur of beams at another offset, or no scan
  // lines at all) put a tenth there; a beam's put nearly all (KITTI: 3e-5..9e-5 RMS against a
  // tenth of the gate of 2e-4..3e-4), even among 20 % background points.
  std::vector<int> near(lines.size(), 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::uint32_t j = nearest[i];
    if (j == kNoLine || sums[j].n < 2) continue;
    const Line& fit = fits[j];
    near[j] += std::abs(points[i].t - fit.a - fit.h * points[i].s) < kNearGate * fit.gate;
  }
  std::vector<Line> refit;
  refit.reserve(lines.size());
  for (std::size_t j = 0; j < lines.size(); ++j) {
    const bool established = lines[j].layer < layer;
    if (sums[j].n < 2) {
      if (established) refit.push_back(lines[j]);  // its points went to a newcomer for now
      continue;
    }
    fits[j].near = near[j] / sums[j].n;
    const bool line = fits[j].near > kMinNearFraction && near[j] >= kMinNear;
    if (established || line) refit.push_back(fits[j]);
  }
  std::sort(refit.begin(), refit.end(), [](const Line& x, const Line& y) { return x.a < y.a; });
  return refit;
}

/// True when line `a` describes its beam better than line `b`: more of its inliers near it (by
/// more than 0.05), else found by an earlier layer, else more inliers.
bool better(const Line& a, const Line& b) {
  if (std::abs(a.near - b.near) > 0.05) return a.near > b.near;
  if (a.layer != b.layer) return a.layer < b.layer;
  return a.inliers > b.inliers;
}

/// Merges neighbouring lines that come closer than kMinBeamSeparation where either has inliers:
/// two beams cannot cross where the cloud has points, so such lines are one beam, found twice by
/// two layers or as two peaks; or one of them is a line an earlier layer drew through beams that
/// lay at one range (a ground ring seen at the wrong offset). Keeps the better one; the next refit
/// moves it.
std::vector<Line> mergeCrossingLines(const std::vector<Line>& lines) {
  std::vector<Line> out;
  for (const Line& line : lines) {
    if (!out.empty()) {
      Line& below = out.back();
      const double s_lo = std::min(line.s_lo, below.s_lo), s_hi = std::max(line.s_hi, below.s_hi);
      const double gap_lo = line.a - below.a + (line.h - below.h) * s_lo;
      const double gap_hi = line.a - below.a + (line.h - below.h) * s_hi;
      if (std::min(gap_lo, gap_hi) < kMinBeamSeparation) {
        if (better(line, below)) below = line;
        continue;
      }
    }
    out.push_back(line);
  }
  return out;
}

}  // namespace

LineSet::LineSet(const std::vector<Line>& lines) : spacing(lines.size(), kMaxSpacing) {
  a.reserve(lines.size());
  h.reserve(lines.size());
  for (const Line& line : lines) {
    a.push_back(line.a);
    h.push_back(line.h);
  }
  for (std::size_t j = 0; j + 1 < lines.size(); ++j) {
    const double gap = a[j + 1] - a[j];
    spacing[j] = std::min(spacing[j], gap);
    spacing[j + 1] = gap;
  }
}

// A branchless binary search for the last line below the point, then that line or the next,
// kBatch points side by side: the points come in any order, so a branching search mispredicts at
// every step, and independent searches overlap in the CPU (3x faster than one at a time).
void nearestLines(const std::vector<LinePoint>& points, const LineSet& lines,
                  std::vector<std::uint32_t>& nearest) {
  nearest.resize(points.size());
  const std::size_t n = lines.a.size();
  if (n == 0) return;
  const double* a = lines.a.data();
  const double* h = lines.h.data();
  for (std::size_t i0 = 0; i0 < points.size(); i0 += kBatch) {
    const std::size_t m = std::min(kBatch, points.size() - i0);
    const LinePoint* q = points.data() + i0;
    std::size_t base[kBatch] = {};
    for (std::size_t len = n; len > 1; len -= len / 2) {
      const std::size_t half = len / 2;
      for (std::size_t k = 0; k < m; ++k) {
        const std::size_t mid = base[k] + half;
        base[k] = a[mid] + h[mid] * q[k].s < q[k].t ? mid : base[k];
      }
    }
    for (std::size_t k = 0; k < m; ++k) {
      const std::size_t j = base[k], up = std::min(j + 1, n - 1);
      const double below = std::abs(q[k].t - a[j] - h[j] * q[k].s);
      const double above = std::abs(q[k].t - a[up] - h[up] * q[k].s);
      nearest[i0 + k] = static_cast<std::uint32_t>(above < below ? up : j);
    }
  }
}

std::vector<Line> refineLines(const std::vector<LinePoint>& sample, std::vector<Line> lines,
                              int layer) {
  for (int round = 0; round < kRefinements && !lines.empty(); ++round) {
    lines = mergeCrossingLines(refitLines(sample, lines, layer));
  }
  return lines.empty() ? lines : refitLines(sample, lines, layer);
}

std::vector<LinePoint> unexplained(const std::vector<LinePoint>& points,
                                   const std::vector<Line>& lines) {
  if (lines.empty()) return points;
  const LineSet set(lines);
  std::vector<std::uint32_t> nearest;
  nearestLines(points, set, nearest);
  std::vector<LinePoint> out;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::uint32_t j = nearest[i];
    if (std::abs(set.residual(j, points[i])) >= kExplainedGate * set.spacing[j]) {
      out.push_back(points[i]);
    }
  }
  return out;
}

}  // namespace beam_model
}  // namespace lidar_stereo_fusion
