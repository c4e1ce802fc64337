// The lines of the beam model (core/ring_recovery.h), shared by the two files that implement it:
// ring_beam_model.cpp finds candidate lines (Hough layers), ring_beam_lines.cpp fits, merges and
// assigns them. Private to the core.
#pragma once

#include <cstdint>
#include <vector>

#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {
namespace beam_model {

/// A finite point in the line plane: s = 1 / r [1/m], t = z / r (float: 1e-7 relative, far below a
/// beam's 5e-5 residual); `index` into the cloud, `hash` of its coordinates for sampling.
struct LinePoint {
  float s = 0.f, t = 0.f;
  std::uint32_t index = 0;
  std::uint32_t hash = 0;
};

/// A beam candidate: the line t = a + h s (a = tan(theta), h = offset [m]).
struct Line {
  double a = 0.0, h = 0.0;
  int layer = 0;  ///< the Hough layer that found it: lines of earlier layers are established
  // After a fit:
  double s_lo = 0.0, s_hi = 0.0;  ///< range of s of its inliers
  double inliers = 0.0;           ///< number of inliers
  double rms = 0.0;               ///< RMS residual of the inliers
  double gate = 0.0;              ///< the inlier gate: residuals below it were inliers
  double near = 0.0;              ///< fraction of the inliers within a tenth of the gate
};

constexpr double kBin = 2e-4;  ///< [tan] histogram bin (0.011 deg; beams are >= 0.1 deg apart)
/// Inliers of a line: residual below this times the spacing to the next line.
constexpr double kInlierGate = 0.35;
/// Points a line "explains": residual below this times the spacing to the next line.
constexpr double kExplainedGate = 0.25;

/// The finite points of `cloud` in the line plane (r below 0.1 m counts as 0.1 m).
std::vector<LinePoint> linePoints(const LidarCloud& cloud);

/// The points that vote in the Hough layers: r >= 1 m, |z / r| <= 3, and about 16384 of them
/// chosen by hash, so that the sample does not depend on the point order.
std::vector<LinePoint> houghSample(const std::vector<LinePoint>& points);

/// The beam lines of the sample, layer by layer (ring_beam_model.cpp), ascending a.
std::vector<Line> findLines(const std::vector<LinePoint>& sample);

/// Lines as arrays, with each line's distance in a to its nearest neighbour (at most 0.05, also
/// for a line without neighbours).
struct LineSet {
  std::vector<double> a, h, spacing;
  explicit LineSet(const std::vector<Line>& lines);
  double residual(std::size_t j, const LinePoint& q) const { return q.t - a[j] - h[j] * q.s; }
};

/// For every point the index of the nearest line at its s (lines ascending in a and not crossing
/// there). Resizes `nearest`.
void nearestLines(const std::vector<LinePoint>& points, const LineSet& lines,
                  std::vector<std::uint32_t>& nearest);

/// Refits the lines on the sample (least squares on their inliers), drops lines of `layer` whose
/// inliers do not form a line and merges lines that cross where they have points, a few times;
/// lines of earlier layers are neither dropped nor merged away by those of `layer`, so that a
/// layer only adds lines. Ascending a.
std::vector<Line> refineLines(const std::vector<LinePoint>& sample, std::vector<Line> lines,
                              int layer);

/// The points of `points` that no line explains (residual >= kExplainedGate times the spacing).
std::vector<LinePoint> unexplained(const std::vector<LinePoint>& points,
                                   const std::vector<Line>& lines);

}  // namespace beam_model
}  // namespace lidar_stereo_fusion
