// Synthetic stereo pairs with exactly known disparity, for the core tests.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {
namespace test {

/// A w x h rectified camera with square pixels, the principal point in the middle and a 0.5 m
/// baseline: fx * baseline = fx / 2 px m.
inline StereoCamera centredCamera(int w, int h, double fx) {
  StereoCamera c;
  c.fx = c.fy = fx;
  c.cx = w / 2.0;
  c.cy = h / 2.0;
  c.baseline = 0.5;
  c.width = w;
  c.height = h;
  return c;
}

/// A smooth, non-periodic colour texture T(u, v): a sum of random sinusoids per channel
/// (wavelengths 6..40 px), evaluated analytically so that any sub-pixel position is exact.
class Texture {
 public:
  explicit Texture(uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> angle(0, 2 * M_PI), wave(6, 40), phase(0, 2 * M_PI);
    for (int c = 0; c < 3; ++c) {
      for (int i = 0; i < 12; ++i) {
        const double th = angle(rng), k = 2 * M_PI / wave(rng);
        waves_[c].push_back({k * std::cos(th), k * std::sin(th), phase(rng)});
      }
    }
  }
  cv::Vec3b at(double u, double v) const {
    cv::Vec3b out;
    for (int c = 0; c < 3; ++c) {
      double s = 0;
      for (const auto& w : waves_[c]) s += std::sin(w[0] * u + w[1] * v + w[2]);
      out[c] = cv::saturate_cast<uchar>(128.0 + 110.0 * s / std::sqrt(12.0 * 0.5) / 2.2);
    }
    return out;
  }

 private:
  std::vector<cv::Vec3d> waves_[3];
};

/// A textured plane with left disparity d(x, y) = a x + b y + c seen by a rectified pair.
struct PlaneScene {
  cv::Mat left, right;  ///< BGR8
  double a, b, c;
  double disparity(int x, int y) const { return a * x + b * y + c; }

  static PlaneScene make(int width, int height, double a, double b, double c, uint64_t seed) {
    PlaneScene s{cv::Mat(height, width, CV_8UC3), cv::Mat(height, width, CV_8UC3), a, b, c};
    const Texture tex(seed);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        s.left.at<cv::Vec3b>(y, x) = tex.at(x, y);
        // Right pixel x_r sees the left point x with x - d(x) = x_r.
        const double xl = (x + b * y + c) / (1.0 - a);
        s.right.at<cv::Vec3b>(y, x) = tex.at(xl, y);
      }
    }
    return s;
  }
};

}  // namespace test
}  // namespace lidar_stereo_fusion
