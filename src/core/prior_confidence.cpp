// Stage 2, last step: the prior's confidence (readings in prior_confidence.h).
#include "lidar_stereo_fusion/core/prior_confidence.h"

#include "lidar_stereo_fusion/core/param_table.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "column_index.h"
#include "scan_line_columns.h"

namespace lidar_stereo_fusion {

namespace {

/// Slope [px/row] of the line pair (a above b), or NaN when it is steeper than max_slope (the
/// pair is itself an edge and predicts nothing).
float pairSlope(const ColumnEntry& a, const ColumnEntry& b, float max_slope) {
  const float s = (b.d - a.d) / static_cast<float>(b.y - a.y);
  return std::abs(s) <= max_slope ? s : std::nanf("");
}

/// Residual r [px] of the interval between lines k and k + 1 of a column (prior_confidence.h).
float intervalResidual(const ColumnEntry* e, int n, int k, float max_slope) {
  const ColumnEntry& up = e[k];
  const ColumnEntry& down = e[k + 1];
  const float gap = static_cast<float>(down.y - up.y);
  float r = std::abs(down.d - up.d);
  if (k >= 1) {
    const float s = pairSlope(e[k - 1], up, max_slope);
    if (std::isfinite(s)) r = std::min(r, std::abs(down.d - (up.d + s * gap)));
  }
  if (k + 2 < n) {
    const float s = pairSlope(down, e[k + 2], max_slope);
    if (std::isfinite(s)) r = std::min(r, std::abs(up.d - (down.d - s * gap)));
  }
  return r;
}

}  // namespace

void PriorConfidenceParams::validate() const { requireRanges("PriorConfidenceParams", *this); }

cv::Mat1f priorConfidence(const ScanLines& lines, const cv::Mat1f& prior,
                          const std::vector<cv::Point>& removed,
                          const PriorConfidenceParams& params) {
  return priorConfidence(ColumnIndex(lines.disparity), lines.disparity, prior, removed, params);
}

IntervalConfidence::IntervalConfidence(const PriorConfidenceParams& params, const cv::Size& size,
                                       const std::vector<cv::Point>& removed)
    : tolerance_(static_cast<float>(params.edge_tolerance)),
      inv_sigma_(static_cast<float>(1.0 / params.edge_sigma)),
      max_slope_(static_cast<float>(params.max_surface_slope)),
      removed_factor_(static_cast<float>(params.removed_factor)),
      near_(static_cast<size_t>(size.height / 2 + 1)),
      removed_rows_(static_cast<size_t>(size.width)) {
  // The distance factor by row distance to the nearer line, tabulated (the same float expression).
  const float near_rows = static_cast<float>(params.near_rows);
  const float inv_decay = params.decay_rows > 0 ? static_cast<float>(1.0 / params.decay_rows) : 0.f;
  for (size_t dist = 0; dist < near_.size(); ++dist) {
    near_[dist] = std::exp(-std::max(0.f, static_cast<float>(dist) - near_rows) * inv_decay);
  }
  for (const cv::Point& p : removed) {
    if (p.x >= 0 && p.x < size.width && p.y >= 0 && p.y < size.height) {
      removed_rows_[static_cast<size_t>(p.x)].push_back(p.y);
    }
  }
  for (auto& r : removed_rows_) std::sort(r.begin(), r.end());
}

float IntervalConfidence::agreement(const ColumnEntry* e, int n, int k, int x) const {
  float a =
      std::exp(-std::max(0.f, intervalResidual(e, n, k, max_slope_) - tolerance_) * inv_sigma_);
  const std::vector<int>& gone = removed_rows_[static_cast<size_t>(x)];
  const auto it = std::upper_bound(gone.begin(), gone.end(), e[k].y);
  if (it != gone.end() && *it < e[k + 1].y) a *= removed_factor_;
  return a;
}

cv::Mat1f priorConfidence(const ColumnIndex& index, const cv::Mat1f& lines, const cv::Mat1f& prior,
                          const std::vector<cv::Point>& removed,
                          const PriorConfidenceParams& params) {
  params.validate();
  if (lines.empty() || prior.empty()) {
    throw std::invalid_argument("priorConfidence: empty scan lines or prior");
  }
  if (lines.size() != prior.size()) {
    throw std::invalid_argument("priorConfidence: scan lines and prior differ in size");
  }
  const IntervalConfidence model(params, prior.size(), removed);
  cv::Mat1f confidence;
  IntervalMaps maps;
  maps.confidence = &confidence;
  scanLineIntervals(index, lines, 0, 0.0, &model, maps, &prior);
  return confidence;
}

namespace {

/// The hole fill's writes: a filled pixel takes the value at the hole fill's confidence.
struct HoleFill {
  cv::Mat1f& prior;
  cv::Mat1f& confidence;
  float hole;
  int filled = 0;
  void set(int y, int x, float value) {
    prior(y, x) = value;
    confidence(y, x) = hole;
    ++filled;
  }
};

/// Rows: a gap between two values takes the nearer (larger) one; the row ends take the first and
/// last value. The LiDAR's view of each column starts at its top value. A row crosses the tops of
/// many columns: the top beam's arc spans rows, and a near object's top point sits higher in the
/// image than a far one's (the LiDAR is above the camera). A row fill that carried a near object's
/// disparity sideways above a column's top would paint near planes over the far surfaces there
/// (bands along the top scan line). So above its top value, a column takes a fill value only if it
/// is no nearer than that top value (+ tolerance): the same surface seen by a neighbour where this
/// column's top beam returned nothing, or one behind it.
void fillRows(HoleFill& f, float tolerance) {
  const cv::Mat1f& prior = f.prior;
  std::vector<int> top(static_cast<size_t>(prior.cols), prior.rows);
  std::vector<float> top_value(static_cast<size_t>(prior.cols),
                               std::numeric_limits<float>::infinity());
  // Each column's first value from the top; the rows below the last column's top are not read.
  int remaining = prior.cols;
  for (int y = 0; y < prior.rows && remaining > 0; ++y) {
    const float* row = prior[y];
    for (int x = 0; x < prior.cols; ++x) {
      if (top[x] == prior.rows && row[x] > 0.f) {
        top[x] = y;
        top_value[x] = row[x];
        --remaining;
      }
    }
  }
  for (int y = 0; y < prior.rows; ++y) {
    const float* d = prior[y];
    const auto fill = [&](int u, float value) {
      if (y >= top[u] || value <= top_value[u] + tolerance) f.set(y, u, value);
    };
    int last = -1;  // column of the last value seen in this row
    for (int x = 0; x < prior.cols; ++x) {
      if (!(d[x] > 0.f)) continue;
      const float value = last < 0 ? d[x] : std::max(d[last], d[x]);
      for (int u = last + 1; u < x; ++u) fill(u, value);
      last = x;
    }
    for (int u = last + 1; last >= 0 && u < prior.cols; ++u) fill(u, d[last]);
  }
}

/// Columns: below the bottom value, the bottom value (the ground the LiDAR's lowest beam missed);
/// above the top value, the top value for `top_rows` rows.
void fillColumnEnds(HoleFill& f, int top_rows) {
  const cv::Mat1f& prior = f.prior;
  for (int x = 0; x < prior.cols; ++x) {
    int y = prior.rows - 1;
    while (y >= 0 && !(prior(y, x) > 0.f)) --y;
    for (int v = y + 1; y >= 0 && v < prior.rows; ++v) f.set(v, x, prior(y, x));
  }
  for (int x = 0; x < prior.cols; ++x) {
    int y = 0;
    while (y < prior.rows && !(prior(y, x) > 0.f)) ++y;
    if (y == prior.rows) continue;
    for (int v = std::max(0, y - top_rows); v < y; ++v) f.set(v, x, prior(y, x));
  }
}

}  // namespace

int fillPriorHoles(cv::Mat1f& prior, cv::Mat1f& confidence, const PriorConfidenceParams& params) {
  params.validate();
  if (prior.size() != confidence.size()) {
    throw std::invalid_argument("fillPriorHoles: prior and confidence differ in size");
  }
  if (params.hole_confidence <= 0) return 0;
  HoleFill fill{prior, confidence, static_cast<float>(params.hole_confidence)};
  fillRows(fill, static_cast<float>(params.edge_tolerance));
  fillColumnEnds(fill, params.top_extension_rows);
  return fill.filled;
}

}  // namespace lidar_stereo_fusion
