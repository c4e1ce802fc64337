// Which surface a reference shows at a method's own depth edges (edge_sides.h).
#include "lidar_stereo_fusion/eval/edge_sides.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace lidar_stereo_fusion {

EdgeSides& EdgeSides::operator+=(const EdgeSides& o) {
  pixels += o.pixels;
  near += o.near;
  far += o.far;
  between += o.between;
  other += o.other;
  edge_sq_error += o.edge_sq_error;
  total_sq_error += o.total_sq_error;
  return *this;
}

namespace {

constexpr int kDy[4] = {-1, 1, 0, 0}, kDx[4] = {0, 0, -1, 1};  ///< the 4-neighbours

bool hasValue(float v) { return std::isfinite(v) && v > 0.f; }

/// The value as a depth-like quantity (larger = farther).
double farness(float v, MapKind kind) { return kind == MapKind::kDepth ? v : 1.0 / v; }

}  // namespace

EdgeSides edgeSides(const cv::Mat1f& output, const cv::Mat1f& reference, MapKind kind,
                    double min_ratio, double tolerance) {
  if (output.size() != reference.size()) {
    throw std::invalid_argument("edgeSides: output and reference differ in size");
  }
  if (!(min_ratio > 1.0) || !(tolerance >= 0.0 && tolerance < 1.0)) {
    throw std::invalid_argument("edgeSides: min_ratio must be > 1 and tolerance in [0, 1)");
  }
  const cv::Mat1f filled = fillLikeDevkit(output, kind);
  EdgeSides s;
  const int rows = filled.rows, cols = filled.cols;
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      const float r = reference(y, x);
      if (!hasValue(r)) continue;
      const float v = filled(y, x);
      const double err = hasValue(v) ? static_cast<double>(v) - r : static_cast<double>(r);
      s.total_sq_error += err * err;
      if (!hasValue(v)) continue;
      const double zp = farness(v, kind);
      double zq = zp;  // the nearest 4-neighbour with a value
      for (int k = 0; k < 4; ++k) {
        const int yy = y + kDy[k], xx = x + kDx[k];
        if (yy < 0 || yy >= rows || xx < 0 || xx >= cols || !hasValue(filled(yy, xx))) continue;
        zq = std::min(zq, farness(filled(yy, xx), kind));
      }
      if (zp < min_ratio * zq) continue;
      const double zr = farness(r, kind);
      ++s.pixels;
      s.edge_sq_error += err * err;
      if (std::abs(zr - zq) <= tolerance * zq) {
        ++s.near;
      } else if (std::abs(zr - zp) <= tolerance * zp) {
        ++s.far;
      } else if (zr > zq && zr < zp) {
        ++s.between;
      } else {
        ++s.other;
      }
    }
  }
  return s;
}

}  // namespace lidar_stereo_fusion
