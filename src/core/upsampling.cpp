// Stage 2: up-sampling of sparse LiDAR disparity. BI* (paper Sec. III-B: scan-line completion,
// Algorithm 1, Eq. 3), BF* (Premebida et al. 2016) and the scan-line search bounds (Sec. III-D).
//
// Column-wise steps (Algorithm 1, Eq. 3, bounds) first index the scan-line pixels by column in one
// row-major pass, then write their results straight into the output; no full-size temporaries
// (fresh full-size buffers cost page faults every frame).
#include "lidar_stereo_fusion/core/upsampling.h"

#include "lidar_stereo_fusion/core/param_table.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "column_index.h"

namespace lidar_stereo_fusion {

namespace {

/// A projected point of one ring.
struct RingPoint {
  int x, y;
  float d;
};

inline int roundToPixel(double v) { return static_cast<int>(std::floor(v + 0.5)); }

void requireDisparityMap(const cv::Mat1f& map, const char* where) {
  if (map.empty()) throw std::invalid_argument(std::string(where) + ": disparity map is empty");
}

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

/// RGB L1 distance in [0, 765]; for grey images 3 |a - b| (a grey pixel as an RGB triple).
inline int colorDistance(const cv::Mat& image, int y0, int y1, int x) {
  if (image.type() == CV_8UC3) {
    const cv::Vec3b& a = image.at<cv::Vec3b>(y0, x);
    const cv::Vec3b& b = image.at<cv::Vec3b>(y1, x);
    return std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]);
  }
  return 3 * std::abs(image.at<uint8_t>(y0, x) - image.at<uint8_t>(y1, x));
}

/// Algorithm 1 test in one direction: does one of the next `search_lines` scan-line pixels from
/// entry k (step -1 = up, +1 = down) lie in front (d' - d > max_disp_diff) with a similar colour?
bool hasSimilarForeground(const ColumnEntry* entries, int n, int k, int step, const cv::Mat& image,
                          int x, const BIParams& params) {
  const ColumnEntry& self = entries[k];
  for (int j = k + step, seen = 0; j >= 0 && j < n && seen < params.search_lines; j += step) {
    ++seen;
    const ColumnEntry& other = entries[j];
    if (other.d - self.d > params.max_disp_diff &&
        colorDistance(image, other.y, self.y, x) < params.max_color_diff) {
      return true;
    }
  }
  return false;
}

/// Writes (x, y, d, ring) with a z-buffer: the nearer value (larger disparity) wins.
inline void writeNearest(ScanLines& lines, int x, int y, float d, short ring) {
  float& stored = lines.disparity(y, x);
  if (d > stored) {
    stored = d;
    lines.ring(y, x) = ring;
  }
}

/// Interpolates one ring between consecutive points (sorted by x) along x.
void completeRing(const std::vector<RingPoint>& points, short ring, const BIParams& params,
                  ScanLines& lines) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    const RingPoint& a = points[i];
    writeNearest(lines, a.x, a.y, a.d, ring);
    if (i + 1 == points.size()) break;
    const RingPoint& b = points[i + 1];
    const int span = b.x - a.x;
    if (span < 2 || span > params.max_gap_px || std::abs(b.d - a.d) > params.max_jump_disp) {
      continue;
    }
    for (int x = a.x + 1; x < b.x; ++x) {
      const double t = static_cast<double>(x - a.x) / span;
      const int y = roundToPixel(a.y + t * (b.y - a.y));
      const double d = a.d + t * (static_cast<double>(b.d) - a.d);
      writeNearest(lines, x, y, static_cast<float>(d), ring);
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

void BIParams::validate() const { requireRanges("BIParams", *this); }

void BFParams::validate() const {
  requireRanges("BFParams", *this);
  const int window = (2 * radius + 1) * (2 * radius + 1);
  if (min_support > window) {
    throw std::invalid_argument("BFParams: min_support must be <= " + std::to_string(window) +
                                " (the window's pixels), got " + std::to_string(min_support));
  }
}

ScanLines completeScanLines(const SparseDisparity& sparse, const BIParams& params) {
  params.validate();
  const cv::Mat1f& disparity = sparse.disparity;
  requireDisparityMap(disparity, "completeScanLines");
  const bool has_ring_map = !sparse.ring.empty();
  if (has_ring_map && sparse.ring.size() != disparity.size()) {
    throw std::invalid_argument("completeScanLines: ring map size differs from disparity size");
  }

  ScanLines lines;
  lines.disparity = cv::Mat1f::zeros(disparity.size());
  lines.ring.create(disparity.size());
  lines.ring.setTo(-1);

  // Group the projected points by ring; ring-less points are written as single pixels.
  std::vector<std::vector<RingPoint>> rings;
  for (int y = 0; y < disparity.rows; ++y) {
    const float* d_row = disparity[y];
    const short* r_row = has_ring_map ? sparse.ring[y] : nullptr;
    for (int x = 0; x < disparity.cols; ++x) {
      const float d = d_row[x];
      if (!(d >= 0.f) || !std::isfinite(d)) {
        throw std::invalid_argument("completeScanLines: disparity at (" + std::to_string(x) + ", " +
                                    std::to_string(y) + ") is not finite and >= 0");
      }
      if (d == 0.f) continue;
      const int ring = r_row ? r_row[x] : -1;
      if (ring < 0) {
        writeNearest(lines, x, y, d, -1);
        continue;
      }
      if (ring >= static_cast<int>(rings.size())) rings.resize(ring + 1);
      rings[ring].push_back({x, y, d});
    }
  }
  for (std::size_t r = 0; r < rings.size(); ++r) {
    std::vector<RingPoint>& points = rings[r];
    std::sort(points.begin(), points.end(), [](const RingPoint& a, const RingPoint& b) {
      return a.x < b.x || (a.x == b.x && a.y < b.y);
    });
    completeRing(points, static_cast<short>(r), params, lines);
  }
  return lines;
}

int removeOccludedPoints(ScanLines& lines, const cv::Mat& image, const BIParams& params,
                         std::vector<cv::Point>* removed_pixels) {
  params.validate();
  requireDisparityMap(lines.disparity, "removeOccludedPoints");
  if (image.size() != lines.disparity.size()) {
    throw std::invalid_argument("removeOccludedPoints: image size differs from the scan lines");
  }
  if (image.type() != CV_8UC3 && image.type() != CV_8UC1) {
    throw std::invalid_argument("removeOccludedPoints: image must be CV_8UC3 (BGR) or CV_8UC1");
  }
  const bool has_ring_map = !lines.ring.empty();
  if (has_ring_map && lines.ring.size() != lines.disparity.size()) {
    throw std::invalid_argument("removeOccludedPoints: ring map size differs from disparity size");
  }

  // Every decision is taken on the input state: the pixels to clear are collected first and
  // cleared afterwards, so the result does not depend on the scan order and a removed background
  // pixel never changes the verdict on another one in the same pass.
  const ColumnIndex index(lines.disparity);
  std::vector<cv::Point> removed;
  for (int x = 0; x < index.cols(); ++x) {
    const ColumnEntry* entries = index.column(x);
    const int n = index.size(x);
    for (int k = 0; k < n; ++k) {
      if (hasSimilarForeground(entries, n, k, -1, image, x, params) &&
          hasSimilarForeground(entries, n, k, +1, image, x, params)) {
        removed.emplace_back(x, entries[k].y);
      }
    }
  }
  for (const cv::Point& p : removed) {
    lines.disparity(p) = 0.f;
    if (has_ring_map) lines.ring(p) = -1;
  }
  const int count = static_cast<int>(removed.size());
  if (removed_pixels) *removed_pixels = std::move(removed);
  return count;
}

cv::Mat1f interpolateBetweenScanLines(const ScanLines& lines, const BIParams& params) {
  params.validate();
  requireDisparityMap(lines.disparity, "interpolateBetweenScanLines");
  const ColumnIndex index(lines.disparity);
  cv::Mat1f out = cv::Mat1f::zeros(lines.disparity.size());
  for (int x = 0; x < index.cols(); ++x) {
    const ColumnEntry* entries = index.column(x);
    const int n = index.size(x);
    for (int k = 0; k < n; ++k) {
      out(entries[k].y, x) = entries[k].d;
      if (k + 1 == n) break;
      const ColumnEntry& up = entries[k];
      const ColumnEntry& down = entries[k + 1];
      const int gap = down.y - up.y;
      if (gap > params.max_interp_rows) continue;
      for (int y = up.y + 1; y < down.y; ++y) {  // Eq. 3
        out(y, x) = static_cast<float>(
            (static_cast<double>(y - up.y) * down.d + static_cast<double>(down.y - y) * up.d) /
            gap);
      }
    }
  }
  return out;
}

cv::Mat1f upsampleBI(const SparseDisparity& sparse, const cv::Mat& image, const BIParams& params,
                     int* removed, ScanLines* lines_out, std::vector<cv::Point>* removed_pixels) {
  ScanLines lines = completeScanLines(sparse, params);
  const int count = removeOccludedPoints(lines, image, params, removed_pixels);
  if (removed) *removed = count;
  cv::Mat1f dense = interpolateBetweenScanLines(lines, params);
  if (lines_out) *lines_out = std::move(lines);
  return dense;
}

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

ScanLineBounds computeScanLineBounds(const ScanLines& lines, double margin_px) {
  requireDisparityMap(lines.disparity, "computeScanLineBounds");
  if (!std::isfinite(margin_px) || margin_px < 0.0) {
    throw std::invalid_argument("computeScanLineBounds: margin_px must be finite and >= 0, got " +
                                std::to_string(margin_px));
  }
  const ColumnIndex index(lines.disparity);
  ScanLineBounds bounds;
  bounds.lo = cv::Mat1f::zeros(lines.disparity.size());
  bounds.hi = cv::Mat1f::zeros(lines.disparity.size());
  bounds.range = cv::Mat1f::zeros(lines.disparity.size());
  for (int x = 0; x < index.cols(); ++x) {
    const ColumnEntry* entries = index.column(x);
    const int n = index.size(x);
    if (n < 2) continue;
    // For row y, "up" is the nearest line strictly above y and "down" the nearest strictly below.
    int next = 0;  // index of the first line with row > y
    for (int y = entries[0].y + 1; y < entries[n - 1].y; ++y) {
      while (next < n && entries[next].y <= y) ++next;
      const int up_index = entries[next - 1].y == y ? next - 2 : next - 1;
      if (up_index < 0 || next >= n) continue;
      const float d_up = entries[up_index].d;
      const float d_down = entries[next].d;
      bounds.lo(y, x) = static_cast<float>(std::min(d_up, d_down) - margin_px);
      bounds.hi(y, x) = static_cast<float>(std::max(d_up, d_down) + margin_px);
      bounds.range(y, x) = std::abs(d_up - d_down);
    }
  }
  return bounds;
}

}  // namespace lidar_stereo_fusion
