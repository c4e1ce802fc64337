// Stage 2: up-sampling of sparse LiDAR disparity. BI* (paper Sec. III-B: scan-line completion,
// Algorithm 1, Eq. 3), the scan-line search bounds (Sec. III-D) and the parameter checks of BI*
// and BF*. BF* itself (Premebida et al. 2016): upsampling_bf.cpp.
//
// Column-wise steps (Algorithm 1, Eq. 3, bounds) first index the scan-line pixels by column in one
// row-major pass, then write their results straight into the output; no full-size temporaries
// (fresh full-size buffers cost page faults every frame). Eq. 3 and the bounds are one row pass
// over that index, shared with the prior's confidence: scan_line_intervals.cpp.
#include "lidar_stereo_fusion/core/upsampling.h"

#include "lidar_stereo_fusion/core/param_table.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "column_index.h"
#include "scan_line_columns.h"
#include "upsampling_checks.h"

namespace lidar_stereo_fusion {

namespace {

/// A projected point of one ring.
struct RingPoint {
  int x, y;
  float d;
};

inline int roundToPixel(double v) { return static_cast<int>(std::floor(v + 0.5)); }

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
    if (span < 2 || span > params.max_gap_px) continue;
    const bool step = std::abs(b.d - a.d) > params.max_jump_disp;
    if (step && !params.step_fill) continue;
    for (int x = a.x + 1; x < b.x; ++x) {
      const double t = static_cast<double>(x - a.x) / span;
      const int y = roundToPixel(a.y + t * (b.y - a.y));
      if (step) {  // a depth edge somewhere between the two: each side to the middle
        const int twice = 2 * (x - a.x);
        writeNearest(lines, x, y,
                     twice < span   ? a.d
                     : twice > span ? b.d
                                    : std::max(a.d, b.d),
                     ring);
        continue;
      }
      const double d = a.d + t * (static_cast<double>(b.d) - a.d);
      writeNearest(lines, x, y, static_cast<float>(d), ring);
    }
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

  // Every value finite and >= 0: OpenCV's vectorised range check (NaN fails it too), then the
  // points alone are visited.
  cv::Point bad;
  if (!cv::checkRange(disparity, true, &bad, 0.0, std::numeric_limits<float>::infinity())) {
    throw std::invalid_argument("completeScanLines: disparity at (" + std::to_string(bad.x) + ", " +
                                std::to_string(bad.y) + ") is not finite and >= 0");
  }
  // Group the projected points by ring; ring-less points are written as single pixels.
  std::vector<std::vector<RingPoint>> rings;
  for (int y = 0; y < disparity.rows; ++y) {
    const float* d_row = disparity[y];
    const short* r_row = has_ring_map ? sparse.ring[y] : nullptr;
    for (int x = 0; x < disparity.cols; ++x) {
      const float d = d_row[x];
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

namespace {

/// Algorithm 1's decisions on the lines' state, by column (the pixels to clear, ordered by column,
/// then row). Every decision is taken on the input state: the pixels are cleared afterwards, so
/// the result does not depend on the scan order and a removed background pixel never changes the
/// verdict on another one in the same pass.
std::vector<cv::Point> occludedPoints(const ColumnIndex& index, const ScanLines& lines,
                                      const cv::Mat& image, const BIParams& params) {
  params.validate();  // (lines.disparity was checked before the index was built on it)
  if (image.size() != lines.disparity.size()) {
    throw std::invalid_argument("removeOccludedPoints: image size differs from the scan lines");
  }
  if (image.type() != CV_8UC3 && image.type() != CV_8UC1) {
    throw std::invalid_argument("removeOccludedPoints: image must be CV_8UC3 (BGR) or CV_8UC1");
  }
  if (!lines.ring.empty() && lines.ring.size() != lines.disparity.size()) {
    throw std::invalid_argument("removeOccludedPoints: ring map size differs from disparity size");
  }
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
  return removed;
}

}  // namespace

int removeOccludedPoints(ScanLines& lines, const cv::Mat& image, const BIParams& params,
                         std::vector<cv::Point>* removed_pixels) {
  std::vector<cv::Point> removed;
  removeOccludedPointsIndexed(lines, image, params, removed);  // (the index is not wanted here)
  const int count = static_cast<int>(removed.size());
  if (removed_pixels) *removed_pixels = std::move(removed);
  return count;
}

ColumnIndex removeOccludedPointsIndexed(ScanLines& lines, const cv::Mat& image,
                                        const BIParams& params, std::vector<cv::Point>& removed) {
  requireDisparityMap(lines.disparity, "removeOccludedPoints");
  ColumnIndex index(lines.disparity);
  removed = occludedPoints(index, lines, image, params);
  const bool has_ring_map = !lines.ring.empty();
  for (const cv::Point& p : removed) {
    lines.disparity(p) = 0.f;
    if (has_ring_map) lines.ring(p) = -1;
  }
  index.erase(removed);
  return index;
}

namespace {

/// The pixels removeParallaxHidden clears, ordered by column, then row; every decision on the
/// input state (as Algorithm 1's).
std::vector<cv::Point> parallaxHiddenPixels(const ColumnIndex& index, const StereoCamera& camera,
                                            const Eigen::Vector3d& o, const BIParams& params) {
  std::vector<cv::Point> hidden;
  const double fb = camera.fx * camera.baseline;
  for (int x = 0; x < index.cols(); ++x) {
    const ColumnEntry* e = index.column(x);
    const int n = index.size(x);
    for (int k = 0; k < n; ++k) {
      for (const int side : {-1, 1}) {  // q above, then below p = e[k]
        const int j = k + side;
        if (j < 0 || j >= n || e[j].d - e[k].d <= params.max_disp_diff) continue;
        const double zp = fb / e[k].d, zq = fb / e[j].d;
        if (!(zp > o.z()) || !(zq > o.z())) continue;  // in front of the LiDAR along z
        // The LiDAR's ray to p at q's depth: o + s (P - o) with z = zq.
        const double py = (e[k].y - camera.cy) * zp / camera.fy;
        const double ray_y = o.y() + (zq - o.z()) / (zp - o.z()) * (py - o.y());
        const double ray_row = camera.cy + camera.fy * ray_y / zq;
        // Rows from p to where the ray lands, on the far side of p from q; q's edge lies between
        // that row and q's, p is hidden when the edge passes p.
        const double beyond = side > 0 ? e[k].y - ray_row : ray_row - e[k].y;
        if (beyond >= std::abs(e[j].y - e[k].y)) {
          hidden.emplace_back(x, e[k].y);
          break;
        }
      }
    }
  }
  return hidden;
}

}  // namespace

void removeParallaxHiddenIndexed(ScanLines& lines, ColumnIndex& index, const StereoCamera& camera,
                                 const Eigen::Vector3d& lidar_origin, const BIParams& params,
                                 std::vector<cv::Point>& removed) {
  if (!params.remove_parallax_hidden) return;
  camera.validate();
  if (!lidar_origin.allFinite()) {
    throw std::invalid_argument("removeParallaxHidden: the LiDAR's origin is not finite");
  }
  const std::vector<cv::Point> hidden = parallaxHiddenPixels(index, camera, lidar_origin, params);
  if (hidden.empty()) return;
  const bool has_ring_map = !lines.ring.empty();
  for (const cv::Point& p : hidden) {
    lines.disparity(p) = 0.f;
    if (has_ring_map) lines.ring(p) = -1;
  }
  index.erase(hidden);
  std::vector<cv::Point> merged;
  merged.reserve(removed.size() + hidden.size());
  std::merge(removed.begin(), removed.end(), hidden.begin(), hidden.end(),
             std::back_inserter(merged), [](const cv::Point& a, const cv::Point& b) {
               return a.x < b.x || (a.x == b.x && a.y < b.y);
             });
  removed.swap(merged);
}

int removeParallaxHidden(ScanLines& lines, const StereoCamera& camera,
                         const Eigen::Vector3d& lidar_origin, const BIParams& params,
                         std::vector<cv::Point>* removed_pixels) {
  params.validate();
  requireDisparityMap(lines.disparity, "removeParallaxHidden");
  ColumnIndex index(lines.disparity);
  std::vector<cv::Point> removed;
  removeParallaxHiddenIndexed(lines, index, camera, lidar_origin, params, removed);
  const int count = static_cast<int>(removed.size());
  if (removed_pixels) *removed_pixels = std::move(removed);
  return count;
}

cv::Mat1f interpolateBetweenScanLines(const ScanLines& lines, const BIParams& params) {
  return interpolateBetweenScanLines(ColumnIndex(lines.disparity), lines.disparity, params);
}

cv::Mat1f interpolateBetweenScanLines(const ColumnIndex& index, const cv::Mat1f& lines,
                                      const BIParams& params) {
  params.validate();
  requireDisparityMap(lines, "interpolateBetweenScanLines");
  cv::Mat1f out;
  IntervalMaps maps;
  maps.prior = &out;
  scanLineIntervals(index, lines, params.max_interp_rows, 0.0, nullptr, maps);  // Eq. 3
  return out;
}

cv::Mat1f upsampleBI(const SparseDisparity& sparse, const cv::Mat& image, const BIParams& params,
                     int* removed, ScanLines* lines_out, std::vector<cv::Point>* removed_pixels) {
  ScanLines lines = completeScanLines(sparse, params);
  std::vector<cv::Point> cleared;
  const ColumnIndex index = removeOccludedPointsIndexed(lines, image, params, cleared);
  if (removed) *removed = static_cast<int>(cleared.size());
  if (removed_pixels) *removed_pixels = std::move(cleared);
  cv::Mat1f dense = interpolateBetweenScanLines(index, lines.disparity, params);
  if (lines_out) *lines_out = std::move(lines);
  return dense;
}

ScanLineBounds computeScanLineBounds(const ScanLines& lines, double margin_px) {
  return computeScanLineBounds(ColumnIndex(lines.disparity), lines.disparity, margin_px);
}

ScanLineBounds computeScanLineBounds(const ColumnIndex& index, const cv::Mat1f& lines,
                                     double margin_px) {
  requireDisparityMap(lines, "computeScanLineBounds");
  if (!std::isfinite(margin_px) || margin_px < 0.0) {
    throw std::invalid_argument("computeScanLineBounds: margin_px must be finite and >= 0, got " +
                                std::to_string(margin_px));
  }
  ScanLineBounds bounds;
  IntervalMaps maps;
  maps.bounds = &bounds;
  scanLineIntervals(index, lines, 0, margin_px, nullptr, maps);
  return bounds;
}

}  // namespace lidar_stereo_fusion
