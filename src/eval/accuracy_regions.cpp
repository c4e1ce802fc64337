// Per-region masks, the nearest-LiDAR fill and map combination of the accuracy protocols.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "lidar_stereo_fusion/core/upsampling.h"
#include "lidar_stereo_fusion/eval/accuracy_protocols.h"

namespace lidar_stereo_fusion {
namespace {

bool hasValue(float v) { return std::isfinite(v) && v > 0.f; }

constexpr double kInf = std::numeric_limits<double>::infinity();

/// 1-D squared-distance transform of `f` (Felzenszwalb & Huttenlocher 2012, lower envelope of
/// parabolas): d[p] = min_q (p - q)^2 + f[q], arg[p] = the minimising q (-1 when every f is inf).
void distanceTransform1d(const std::vector<double>& f, std::vector<double>& d,
                         std::vector<int>& arg) {
  const int n = static_cast<int>(f.size());
  std::vector<int> v(n);
  std::vector<double> z(n + 1);
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] == kInf) continue;
    double s = -kInf;
    while (k >= 0) {
      s = ((f[q] + double(q) * q) - (f[v[k]] + double(v[k]) * v[k])) / (2.0 * (q - v[k]));
      if (s > z[k]) break;
      --k;
    }
    ++k;
    v[k] = q;
    z[k] = k == 0 ? -kInf : s;
    z[k + 1] = kInf;
  }
  d.assign(n, kInf);
  arg.assign(n, -1);
  if (k < 0) return;
  int j = 0;
  for (int p = 0; p < n; ++p) {
    while (z[j + 1] < p) ++j;
    d[p] = double(p - v[j]) * (p - v[j]) + f[v[j]];
    arg[p] = v[j];
  }
}

}  // namespace

std::string regionName(Region region) {
  switch (region) {
    case Region::kAll:
      return "all";
    case Region::kAbove:
      return "above";
    case Region::kInside:
      return "inside";
    case Region::kEdge:
      return "edge";
    case Region::kElsewhere:
      return "elsewhere";
    case Region::kNear:
      return "< 10 m";
    case Region::kMid:
      return "10-30 m";
    case Region::kFar:
      return ">= 30 m";
    case Region::kAboveBothViews:
      return "above, both views";
    case Region::kTopRows:
      return "rows < " + std::to_string(kTopRowsEnd);
  }
  return "unknown";
}

const cv::Mat1b& RegionMasks::mask(Region region) const {
  static const cv::Mat1b none;
  switch (region) {
    case Region::kAbove:
      return above;
    case Region::kInside:
      return inside;
    case Region::kEdge:
      return edge;
    case Region::kElsewhere:
      return elsewhere;
    case Region::kNear:
      return near;
    case Region::kMid:
      return mid;
    case Region::kFar:
      return far;
    case Region::kAboveBothViews:
      return above_both_views;
    case Region::kTopRows:
      return top_rows;
    case Region::kAll:
      break;
  }
  return none;
}

void RegionMasks::setDepthBands(const cv::Mat1f& reference_depth) {
  if (reference_depth.size() != above.size()) {
    throw std::invalid_argument("RegionMasks::setDepthBands: the reference differs in size");
  }
  near = cv::Mat1b(reference_depth.size(), uchar(0));
  mid = near.clone();
  far = near.clone();
  top_rows = near.clone();
  top_rows.rowRange(0, std::min(kTopRowsEnd, top_rows.rows)).setTo(255);
  for (int y = 0; y < reference_depth.rows; ++y) {
    for (int x = 0; x < reference_depth.cols; ++x) {
      const float z = reference_depth(y, x);
      if (!hasValue(z)) continue;
      (z < kNearBandMax ? near : z < kFarBandMin ? mid : far)(y, x) = 255;
    }
  }
}

RegionMasks computeRegionMasks(const SparseDisparity& fed, const cv::Mat& image,
                               double edge_range_px) {
  if (fed.disparity.empty()) throw std::invalid_argument("computeRegionMasks: empty sparse map");
  if (image.size() != fed.disparity.size()) {
    throw std::invalid_argument("computeRegionMasks: image and sparse map differ in size");
  }
  const int rows = fed.disparity.rows, cols = fed.disparity.cols;
  RegionMasks masks;
  masks.above = cv::Mat1b(rows, cols, uchar(0));
  for (int x = 0; x < cols; ++x) {
    int top = 0;
    while (top < rows && !hasValue(fed.disparity(top, x))) ++top;
    for (int y = 0; y < top; ++y) masks.above(y, x) = 255;
  }
  masks.inside = 255 - masks.above;

  // The default BI* scan lines, as the pipeline's prior uses them, but with the paper's gaps
  // across jumps (step_fill off): the regions stay those of earlier releases, comparable.
  BIParams bi;
  bi.step_fill = false;
  ScanLines lines = completeScanLines(fed, bi);
  removeOccludedPoints(lines, image, bi);
  const ScanLineBounds bounds = computeScanLineBounds(lines, 0.0);
  masks.edge = cv::Mat1b(rows, cols, uchar(0));
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      const bool between = bounds.hi(y, x) > 0.f && lines.disparity(y, x) <= 0.f;
      if (masks.inside(y, x) && between && bounds.range(y, x) > edge_range_px) {
        masks.edge(y, x) = 255;
      }
    }
  }
  masks.elsewhere = masks.inside - masks.edge;
  masks.near = cv::Mat1b(rows, cols, uchar(0));
  masks.mid = masks.near.clone();
  masks.far = masks.near.clone();
  masks.above_both_views = masks.near.clone();
  masks.top_rows = masks.near.clone();
  return masks;
}

cv::Mat1f nearestFill(const cv::Mat1f& fed) {
  if (fed.empty()) throw std::invalid_argument("nearestFill: empty map");
  const int rows = fed.rows, cols = fed.cols;
  // Pass 1, per column: squared distance to the nearest valued row and that row.
  cv::Mat1d column_d2(rows, cols);
  cv::Mat1i column_src(rows, cols);
  std::vector<double> f(rows), d;
  std::vector<int> arg;
  for (int x = 0; x < cols; ++x) {
    for (int y = 0; y < rows; ++y) f[y] = hasValue(fed(y, x)) ? 0.0 : kInf;
    distanceTransform1d(f, d, arg);
    for (int y = 0; y < rows; ++y) {
      column_d2(y, x) = d[y];
      column_src(y, x) = arg[y];
    }
  }
  // Pass 2, per row: min over columns x' of (x - x')^2 + column_d2(y, x').
  cv::Mat1f out(rows, cols, 0.f);
  f.resize(cols);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) f[x] = column_d2(y, x);
    distanceTransform1d(f, d, arg);
    for (int x = 0; x < cols; ++x) {
      if (arg[x] < 0) continue;  // no valued pixel at all
      out(y, x) = fed(column_src(y, arg[x]), arg[x]);
    }
  }
  return out;
}

cv::Mat1f combineMaps(const cv::Mat1f& primary, const cv::Mat1f& fallback) {
  if (primary.size() != fallback.size()) {
    throw std::invalid_argument("combineMaps: the two maps differ in size");
  }
  cv::Mat1f out(primary.size(), 0.f);
  for (int y = 0; y < out.rows; ++y) {
    for (int x = 0; x < out.cols; ++x) {
      if (hasValue(primary(y, x))) {
        out(y, x) = primary(y, x);
      } else if (hasValue(fallback(y, x))) {
        out(y, x) = fallback(y, x);
      }
    }
  }
  return out;
}

void RegionMasks::setInBothViews(const cv::Mat1f& reference_disparity) {
  if (reference_disparity.size() != above.size()) {
    throw std::invalid_argument("RegionMasks::setInBothViews: the reference differs in size");
  }
  above_both_views = cv::Mat1b(above.size(), uchar(0));
  for (int y = 0; y < above.rows; ++y) {
    for (int x = 0; x < above.cols; ++x) {
      const float d = reference_disparity(y, x);
      if (above(y, x) && hasValue(d) && static_cast<float>(x) - d >= 0.f) {
        above_both_views(y, x) = 255;
      }
    }
  }
}

}  // namespace lidar_stereo_fusion
