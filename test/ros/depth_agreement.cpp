#include "depth_agreement.h"

#include <algorithm>
#include <cmath>

namespace lidar_stereo_fusion {
namespace test {

RunnerAgreement agreeWithRunner(const cv::Mat1f& z_in, const cv::Mat1f& z_runner, double fB) {
  RunnerAgreement a;
  a.pixels = z_in.rows * z_in.cols;
  double sum_abs = 0;
  for (int y = 0; y < z_in.rows; ++y) {
    for (int x = 0; x < z_in.cols; ++x) {
      const float z = z_in(y, x), zr = z_runner(y, x);
      const bool has = std::isfinite(z) && z > 0, has_runner = zr > 0;
      if (has != has_runner) ++a.validity_differs;
      if (!has || !has_runner) continue;
      ++a.both;
      const double z_png = std::clamp(std::round(z * 256.0), 1.0, 65535.0) / 256.0;
      const double diff = std::abs(fB / z_png - fB / zr);
      if (diff > 1.0) {
        ++a.bad_1px;
      } else {
        sum_abs += diff;
      }
    }
  }
  // Mean over the pixels that agree within 1 px.
  a.mean_abs = a.both > a.bad_1px ? sum_abs / (a.both - a.bad_1px) : 0.0;
  return a;
}

cv::Mat_<uint16_t> kittiDepthValues(const cv::Mat1f& z) {
  cv::Mat_<uint16_t> raw(z.size(), uint16_t{0});
  for (int y = 0; y < z.rows; ++y) {
    for (int x = 0; x < z.cols; ++x) {
      if (!std::isfinite(z(y, x)) || z(y, x) <= 0.f) continue;
      raw(y, x) = static_cast<uint16_t>(std::clamp(std::round(z(y, x) * 256.0), 1.0, 65535.0));
    }
  }
  return raw;
}

}  // namespace test
}  // namespace lidar_stereo_fusion
