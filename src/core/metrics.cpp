// KITTI depth-completion metrics (devkit conventions) and disparity bad-pixel rates.
#include "lidar_stereo_fusion/core/metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace lidar_stereo_fusion {
namespace {

bool hasValue(float v) { return std::isfinite(v) && v > 0.f; }

void requireSameSize(const cv::Mat& estimate, const cv::Mat& reference, const char* who) {
  if (reference.empty()) throw std::invalid_argument(std::string(who) + ": empty reference");
  if (estimate.size() != reference.size()) {
    throw std::invalid_argument(
        std::string(who) + ": estimate is " + std::to_string(estimate.cols) + "x" +
        std::to_string(estimate.rows) + " but the reference is " + std::to_string(reference.cols) +
        "x" + std::to_string(reference.rows));
  }
}

/// Running sums of one image.
struct DepthSums {
  double abs = 0, sq = 0, inv_abs = 0, inv_sq = 0;
  long bad2 = 0, bad3 = 0, bad5 = 0, covered = 0, count = 0;

  /// z, z_ref [m]; z = 0 when the estimate has no value. fb = fx * B [px m].
  void add(double z, double z_ref, double fb) {
    const double err = std::abs(z - z_ref);
    // No estimate: inverse depth 0 (infinitely far), i.e. error 1 / z_ref (1/0 would be inf).
    const double inv_err = std::abs((z > 0 ? 1.0 / z : 0.0) - 1.0 / z_ref);
    const double disp_err = std::abs((z > 0 ? fb / z : 0.0) - fb / z_ref);
    abs += err;
    sq += err * err;
    inv_abs += inv_err;
    inv_sq += inv_err * inv_err;
    bad2 += disp_err > 2.0;
    bad3 += disp_err > 3.0;
    bad5 += disp_err > 5.0;
    ++count;
  }
};

}  // namespace

DepthMetrics evaluateDepth(const cv::Mat1f& depth, const cv::Mat1f& reference,
                           const StereoCamera& camera, bool only_covered) {
  requireSameSize(depth, reference, "evaluateDepth");
  camera.validate();
  const double fb = camera.fx * camera.baseline;
  DepthSums sums;
  long reference_pixels = 0;
  for (int y = 0; y < reference.rows; ++y) {
    for (int x = 0; x < reference.cols; ++x) {
      const float z_ref = reference(y, x);
      if (!hasValue(z_ref)) continue;
      ++reference_pixels;
      const bool covered = hasValue(depth(y, x));
      sums.covered += covered;
      if (!covered && only_covered) continue;
      sums.add(covered ? depth(y, x) : 0.0, z_ref, fb);
    }
  }
  DepthMetrics m;
  m.count = static_cast<int>(sums.count);
  m.coverage = reference_pixels > 0 ? static_cast<double>(sums.covered) / reference_pixels : 0.0;
  if (sums.count == 0) return m;
  const double n = static_cast<double>(sums.count);
  m.mae_mm = 1000.0 * sums.abs / n;  // m -> mm
  m.rmse_mm = 1000.0 * std::sqrt(sums.sq / n);
  m.imae_per_km = 1000.0 * sums.inv_abs / n;  // 1/m -> 1/km
  m.irmse_per_km = 1000.0 * std::sqrt(sums.inv_sq / n);
  m.bad2 = sums.bad2 / n;
  m.bad3 = sums.bad3 / n;
  m.bad5 = sums.bad5 / n;
  return m;
}

DisparityMetrics evaluateDisparity(const cv::Mat1f& disparity, const cv::Mat1f& reference) {
  requireSameSize(disparity, reference, "evaluateDisparity");
  double abs = 0, sq = 0;
  long bad1 = 0, bad2 = 0, bad3 = 0, bad5 = 0, covered = 0, count = 0;
  for (int y = 0; y < reference.rows; ++y) {
    for (int x = 0; x < reference.cols; ++x) {
      const float d_ref = reference(y, x);
      if (!hasValue(d_ref)) continue;
      const float d = disparity(y, x);
      const bool has = hasValue(d);
      covered += has;
      const double err = has ? std::abs(static_cast<double>(d) - d_ref) : d_ref;
      abs += err;
      sq += err * err;
      bad1 += err > 1.0;
      bad2 += err > 2.0;
      bad3 += err > 3.0;
      bad5 += err > 5.0;
      ++count;
    }
  }
  DisparityMetrics m;
  m.count = static_cast<int>(count);
  if (count == 0) return m;
  const double n = static_cast<double>(count);
  m.mae_px = abs / n;
  m.rmse_px = std::sqrt(sq / n);
  m.bad1 = bad1 / n;
  m.bad2 = bad2 / n;
  m.bad3 = bad3 / n;
  m.bad5 = bad5 / n;
  m.coverage = covered / n;
  return m;
}

// Follows the loops of KITTI devkit_depth cpp/io_depth.h, DepthImage::interpolateBackground()
// (Andreas Geiger; identical structure in the stereo devkit's io_disp.h): row gaps with u1 > 0 and
// u2 < width - 1 take std::min(depth left, depth right), then left/right extrapolation per row,
// then top/bottom extrapolation per column. "Valid" there is >= 0 with -1 for missing; here > 0.
cv::Mat1f fillLikeDevkit(const cv::Mat1f& map, MapKind kind) {
  cv::Mat1f out(map.size(), 0.f);
  for (int y = 0; y < map.rows; ++y) {
    for (int x = 0; x < map.cols; ++x) out(y, x) = hasValue(map(y, x)) ? map(y, x) : 0.f;
  }
  const auto nearer = [kind](float a, float b) {
    return kind == MapKind::kDepth ? std::min(a, b) : std::max(a, b);
  };
  const int w = out.cols, h = out.rows;
  for (int y = 0; y < h; ++y) {
    float* row = out[y];
    int count = 0;  // empty pixels since the last estimate
    for (int x = 0; x < w; ++x) {
      if (row[x] <= 0.f) {
        ++count;
        continue;
      }
      const int u1 = x - count, u2 = x - 1;
      if (count >= 1 && u1 > 0 && u2 < w - 1) {
        const float value = nearer(row[u1 - 1], row[u2 + 1]);
        for (int u = u1; u <= u2; ++u) row[u] = value;
      }
      count = 0;
    }
    int first = 0;
    while (first < w && row[first] <= 0.f) ++first;
    if (first == w) continue;  // no estimate in this row
    for (int x = 0; x < first; ++x) row[x] = row[first];
    int last = w - 1;
    while (row[last] <= 0.f) --last;
    for (int x = last + 1; x < w; ++x) row[x] = row[last];
  }
  for (int x = 0; x < w; ++x) {
    int first = 0;
    while (first < h && out(first, x) <= 0.f) ++first;
    if (first == h) continue;
    for (int y = 0; y < first; ++y) out(y, x) = out(first, x);
    int last = h - 1;
    while (out(last, x) <= 0.f) --last;
    for (int y = last + 1; y < h; ++y) out(y, x) = out(last, x);
  }
  return out;
}

DepthMetrics averageMetrics(const std::vector<DepthMetrics>& per_image) {
  DepthMetrics mean;
  int images = 0;
  for (const DepthMetrics& m : per_image) {
    if (m.count == 0) continue;  // an image without reference pixels has no score
    ++images;
    mean.mae_mm += m.mae_mm;
    mean.rmse_mm += m.rmse_mm;
    mean.imae_per_km += m.imae_per_km;
    mean.irmse_per_km += m.irmse_per_km;
    mean.bad2 += m.bad2;
    mean.bad3 += m.bad3;
    mean.bad5 += m.bad5;
    mean.coverage += m.coverage;
    mean.count += m.count;
  }
  if (images == 0) return DepthMetrics();
  for (double* v : {&mean.mae_mm, &mean.rmse_mm, &mean.imae_per_km, &mean.irmse_per_km, &mean.bad2,
                    &mean.bad3, &mean.bad5, &mean.coverage}) {
    *v /= images;
  }
  return mean;
}

DisparityMetrics averageMetrics(const std::vector<DisparityMetrics>& per_image) {
  DisparityMetrics mean;
  int images = 0;
  for (const DisparityMetrics& m : per_image) {
    if (m.count == 0) continue;
    ++images;
    mean.mae_px += m.mae_px;
    mean.rmse_px += m.rmse_px;
    mean.bad1 += m.bad1;
    mean.bad2 += m.bad2;
    mean.bad3 += m.bad3;
    mean.bad5 += m.bad5;
    mean.coverage += m.coverage;
    mean.count += m.count;
  }
  if (images == 0) return DisparityMetrics();
  for (double* v : {&mean.mae_px, &mean.rmse_px, &mean.bad1, &mean.bad2, &mean.bad3, &mean.bad5,
                    &mean.coverage}) {
    *v /= images;
  }
  return mean;
}

}  // namespace lidar_stereo_fusion
