// Stage 2, BF*: bilateral up-sampling of the sparse LiDAR disparity (Premebida et al. 2016), the
// baseline the paper compares BI* with. BFParams::validate() and BI* are in upsampling.cpp.
//
// Each output row walks the LiDAR points of its window rows, ordered by column, with two cursors;
// the range weights come from a table.
#include "lidar_stereo_fusion/core/upsampling.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "upsampling_checks.h"

namespace lidar_stereo_fusion {

namespace {

/// Throws std::invalid_argument naming `where` and the pixel when a value is not finite and >= 0.
void requireValidValues(const cv::Mat1f& map, const char* where) {
  for (int y = 0; y < map.rows; ++y) {
    const float* row = map[y];
    for (int x = 0; x < map.cols; ++x) {
      if (!(row[x] >= 0.f) || !std::isfinite(row[x])) {
        throw std::invalid_argument(std::string(where) + ": disparity at (" + std::to_string(x) +
                                    ", " + std::to_string(y) + ") is " + std::to_string(row[x]) +
                                    "; values must be finite and >= 0 (0 = empty)");
      }
    }
  }
}

/// Range-weight table exp(-delta^2 / (2 sigma^2)) for delta >= 0, linearly interpolated.
/// Deltas beyond the table (weight < e^-40) get weight 0.
class RangeWeightTable {
 public:
  explicit RangeWeightTable(double sigma) {
    scale_ = kStepsPerSigma / sigma;
    const int size = static_cast<int>(std::ceil(std::sqrt(80.0) * kStepsPerSigma)) + 2;  // e^-40
    table_.resize(size);
    for (int i = 0; i < size; ++i) {
      const double delta = i / scale_;
      table_[i] = std::exp(-delta * delta / (2.0 * sigma * sigma));
    }
    last_ = static_cast<double>(size - 1);
  }
  double operator()(double delta) const {
    const double pos = delta * scale_;
    if (pos >= last_) return 0.0;
    const int i = static_cast<int>(pos);
    const double frac = pos - i;
    return table_[i] + frac * (table_[i + 1] - table_[i]);
  }

 private:
  static constexpr double kStepsPerSigma = 256.0;
  std::vector<double> table_;
  double scale_ = 1.0;
  double last_ = 0.0;
};

/// Sparse points of one row: column and disparity, ordered by column.
struct RowPoint {
  int x;
  float d;
};

/// A LiDAR point of the BF* window rows: column, window row (0 .. 2r) and disparity.
struct WindowPoint {
  int x;
  int window_row;
  float d;
};

/// The points of rows y - r .. y + r, ordered by column.
void collectWindowRows(const std::vector<std::vector<RowPoint>>& row_points, int y, int r,
                       std::vector<WindowPoint>& window) {
  window.clear();
  const int rows = static_cast<int>(row_points.size());
  for (int yy = std::max(0, y - r); yy <= std::min(rows - 1, y + r); ++yy) {
    for (const RowPoint& p : row_points[yy]) window.push_back({p.x, yy - y + r, p.d});
  }
  std::sort(window.begin(), window.end(),
            [](const WindowPoint& a, const WindowPoint& b) { return a.x < b.x; });
}

/// BF* of one output row. `window` holds the points of the window rows ordered by column; two
/// cursors keep [first, last) = the points with |x' - x| <= r as x sweeps the row.
void filterRow(const std::vector<WindowPoint>& window, const std::vector<double>& spatial, int side,
               const RangeWeightTable& range_weight, int min_support, int r, float* out, int cols) {
  std::size_t first = 0, last = 0;
  const std::size_t n = window.size();
  for (int x = 0; x < cols; ++x) {
    while (first < n && window[first].x < x - r) ++first;
    while (last < n && window[last].x <= x + r) ++last;
    if (static_cast<int>(last - first) < min_support) continue;
    float ref = 0.f;  // the nearest point (largest disparity) of the window
    for (std::size_t k = first; k < last; ++k) ref = std::max(ref, window[k].d);
    double sum_w = 0.0, sum_wd = 0.0;
    for (std::size_t k = first; k < last; ++k) {
      const WindowPoint& p = window[k];
      const double delta = static_cast<double>(ref) - p.d;
      const double w = spatial[p.window_row * side + (p.x - x + r)] * range_weight(delta);
      sum_w += w;
      sum_wd -= w * delta;
    }
    if (sum_w > 0.0) out[x] = static_cast<float>(ref + sum_wd / sum_w);
  }
}

}  // namespace

cv::Mat1f upsampleBF(const SparseDisparity& sparse, const BFParams& params) {
  // Premebida et al. 2016 up-sample the projected LiDAR map with a bilateral filter whose range
  // kernel is taken relative to the nearest point of the mask, so that the foreground wins at
  // depth edges. Here, per output pixel p with LiDAR points q in the (2r+1)^2 window:
  //   ref = max_q d_q (nearest point), w_q = G_space(|p - q|) * G_range(ref - d_q),
  //   D(p) = sum w_q d_q / sum w_q,
  // evaluated as ref + sum w_q (d_q - ref) / sum w_q (exact when all d_q are equal). Disparity
  // replaces their depth, so sigma_range is in px. Their DBSCAN clustering of the mask (an extra
  // edge treatment) is not implemented: this is the plain filter, without occlusion handling.
  params.validate();
  const cv::Mat1f& sparse_d = sparse.disparity;
  requireDisparityMap(sparse_d, "upsampleBF");
  requireValidValues(sparse_d, "upsampleBF");
  const int r = params.radius;
  const int rows = sparse_d.rows;
  const int cols = sparse_d.cols;

  std::vector<std::vector<RowPoint>> row_points(rows);
  for (int y = 0; y < rows; ++y) {
    const float* d_row = sparse_d[y];
    for (int x = 0; x < cols; ++x) {
      if (d_row[x] > 0.f) row_points[y].push_back({x, d_row[x]});
    }
  }
  const int side = 2 * r + 1;
  std::vector<double> spatial(side * side);
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      spatial[(dy + r) * side + (dx + r)] =
          std::exp(-(dx * dx + dy * dy) / (2.0 * params.sigma_space * params.sigma_space));
    }
  }
  const RangeWeightTable range_weight(params.sigma_range);

  cv::Mat1f out = cv::Mat1f::zeros(rows, cols);
  // Rows are independent; small maps are not worth waking the thread team.
#pragma omp parallel if (rows * cols > 100000)
  {
    std::vector<WindowPoint> window;  // points of rows y - r .. y + r, ordered by column
#pragma omp for schedule(dynamic, 4)
    for (int y = 0; y < rows; ++y) {
      collectWindowRows(row_points, y, r, window);
      filterRow(window, spatial, side, range_weight, params.min_support, r, out[y], cols);
    }
  }
  return out;
}

}  // namespace lidar_stereo_fusion
