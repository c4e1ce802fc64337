// Best sub-pixel shift between a left patch at a LiDAR pixel and the right image (ZNCC).
#include "lidar_stereo_fusion/eval/photometric_check.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace lidar_stereo_fusion {
namespace {

cv::Mat1f toGrey(const cv::Mat& image, const char* what) {
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
    throw std::invalid_argument(std::string("photometricShifts: ") + what +
                                " must be 8-bit BGR or grey");
  }
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  cv::Mat1f out;
  grey.convertTo(out, CV_32F);
  return out;
}

/// Bilinear sample of `image` at (x, y); the caller keeps x in [0, cols - 1), y integer.
float sampleRow(const cv::Mat1f& image, double x, int y) {
  const int x0 = static_cast<int>(std::floor(x));
  const float a = static_cast<float>(x - x0);
  const float* row = image[y];
  return (1.f - a) * row[x0] + a * row[std::min(x0 + 1, image.cols - 1)];
}

/// ZNCC of two equally long patches; `a` has its mean removed and norm `a_norm`.
double zncc(const std::vector<float>& a, double a_norm, const std::vector<float>& b) {
  double mean = 0.0;
  for (const float x : b) mean += x;
  mean /= static_cast<double>(b.size());
  double dot = 0.0, norm = 0.0;
  for (size_t i = 0; i < b.size(); ++i) {
    const double y = b[i] - mean;
    dot += a[i] * y;
    norm += y * y;
  }
  return norm > 0.0 ? dot / std::sqrt(a_norm * norm) : -1.0;
}

/// The median of a non-empty list (the mean of the middle two for an even count).
double median(std::vector<double> values) {
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  double m = values[mid];
  if (values.size() % 2 == 0)
    m = 0.5 * (m + *std::max_element(values.begin(), values.begin() + mid));
  return m;
}

}  // namespace

void PhotometricCheckParams::validate() const {
  if (patch_radius < 1) throw std::invalid_argument("photometric check: patch_radius must be >= 1");
  if (!(step > 0.0)) throw std::invalid_argument("photometric check: step must be > 0");
  if (!(max_shift >= step)) {
    throw std::invalid_argument("photometric check: max_shift must be >= step");
  }
  if (!(min_patch_std >= 0.0)) {
    throw std::invalid_argument("photometric check: min_patch_std must be >= 0");
  }
}

std::optional<double> bestShift(const cv::Mat1f& left, const cv::Mat1f& right, int u, int v,
                                double d, const PhotometricCheckParams& params) {
  const int r = params.patch_radius;
  const double x_first = u - d - params.max_shift - r, x_last = u - d + params.max_shift + r;
  if (u - r < 0 || u + r >= left.cols || v - r < 0 || v + r >= left.rows || x_first < 0.0 ||
      x_last >= right.cols - 1 || !std::isfinite(d)) {
    return std::nullopt;
  }
  std::vector<float> a;
  double mean = 0.0;
  for (int j = -r; j <= r; ++j) {
    for (int i = -r; i <= r; ++i) a.push_back(left(v + j, u + i));
  }
  for (const float x : a) mean += x;
  mean /= static_cast<double>(a.size());
  double a_norm = 0.0;
  for (float& x : a) {
    x = static_cast<float>(x - mean);
    a_norm += x * x;
  }
  if (std::sqrt(a_norm / static_cast<double>(a.size())) < params.min_patch_std || a_norm == 0.0) {
    return std::nullopt;
  }
  const int steps = static_cast<int>(std::floor(params.max_shift / params.step + 1e-9));
  std::vector<double> scores;
  std::vector<float> b(a.size());
  for (int k = -steps; k <= steps; ++k) {
    const double x = u - d + k * params.step;
    size_t n = 0;
    for (int j = -r; j <= r; ++j) {
      for (int i = -r; i <= r; ++i) b[n++] = sampleRow(right, x + i, v + j);
    }
    scores.push_back(zncc(a, a_norm, b));
  }
  const size_t best =
      static_cast<size_t>(std::max_element(scores.begin(), scores.end()) - scores.begin());
  if (best == 0 || best + 1 == scores.size()) return std::nullopt;
  // Parabola through the best step and its neighbours: vertex offset in steps, in (-0.5, 0.5).
  const double s0 = scores[best - 1], s1 = scores[best], s2 = scores[best + 1];
  const double curvature = s0 - 2.0 * s1 + s2;
  const double offset = curvature < 0.0 ? 0.5 * (s0 - s2) / curvature : 0.0;
  return (static_cast<double>(best) - steps + offset) * params.step;
}

PhotometricShifts photometricShifts(const cv::Mat& left_bgr, const cv::Mat& right_bgr,
                                    const cv::Mat1f& sparse_disparity,
                                    const PhotometricCheckParams& params) {
  params.validate();
  if (left_bgr.size() != right_bgr.size() || left_bgr.size() != sparse_disparity.size()) {
    throw std::invalid_argument("photometricShifts: images and disparity differ in size");
  }
  const cv::Mat1f left = toGrey(left_bgr, "left image"), right = toGrey(right_bgr, "right image");
  PhotometricShifts out;
  for (int v = 0; v < sparse_disparity.rows; ++v) {
    for (int u = 0; u < sparse_disparity.cols; ++u) {
      const float d = sparse_disparity(v, u);
      if (!(d > 0.f)) continue;
      ++out.lidar_pixels;
      const std::optional<double> shift = bestShift(left, right, u, v, d, params);
      if (shift) {
        out.shifts.push_back(*shift);
      } else {
        ++out.unscored;
      }
    }
  }
  return out;
}

ShiftSummary summarizeShifts(const std::vector<double>& shifts, double within) {
  ShiftSummary summary;
  summary.count = static_cast<int>(shifts.size());
  if (shifts.empty()) return summary;
  std::vector<double> magnitudes;
  int inside = 0;
  for (const double s : shifts) {
    magnitudes.push_back(std::abs(s));
    if (std::abs(s) <= within) ++inside;
  }
  summary.median = median(shifts);
  summary.median_abs = median(magnitudes);
  summary.fraction_within = static_cast<double>(inside) / static_cast<double>(shifts.size());
  return summary;
}

std::string formatShiftTable(const std::vector<ShiftRow>& rows) {
  const bool any_after =
      std::any_of(rows.begin(), rows.end(), [](const ShiftRow& r) { return r.after.has_value(); });
  std::ostringstream out;
  out << "| frame | scored px | median delta [px] | median abs delta [px] | abs delta <= 0.5 px |";
  if (any_after) {
    out << " scored px, deskewed | median delta | median abs delta | abs delta <= 0.5 px |";
  }
  out << "\n|---|---:|---:|---:|---:|" << (any_after ? "---:|---:|---:|---:|" : "") << "\n";
  auto cells = [&out](const ShiftSummary& s) {
    out << " " << s.count << " | " << std::fixed << std::setprecision(3) << s.median << " | "
        << s.median_abs << " | " << std::setprecision(1) << 100.0 * s.fraction_within << " % |";
  };
  for (const ShiftRow& row : rows) {
    out << "| " << row.name << " |";
    cells(row.before);
    if (row.after) {
      cells(*row.after);
    } else if (any_after) {
      out << " - | - | - | - |";
    }
    out << "\n";
  }
  return out.str();
}

}  // namespace lidar_stereo_fusion
