// Comparing a depth map with kitti_runner's depth PNG of the same frame, for the KITTI bag tests
// (the nodelet's published depth, bag_runner's PNG): in disparity (f B / z), since a far pixel's
// depth is ill-conditioned, after rounding as the KITTI PNG does.
#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

namespace lidar_stereo_fusion {
namespace test {

struct RunnerAgreement {
  int pixels = 0;            ///< of the image
  int both = 0;              ///< pixels with a depth in both
  int validity_differs = 0;  ///< pixels with a depth in one only
  int bad_1px = 0;           ///< pixels whose disparities differ by more than 1 px
  double mean_abs = 0;       ///< [px] mean |disparity difference| of the others
};

/// Depth `z` [m] (NaN / <= 0 = none; rounded to 1/256 m as the PNG does) against `z_runner` [m]
/// (0 = none), both of the same size; `fB` = fx * baseline [px m].
RunnerAgreement agreeWithRunner(const cv::Mat1f& z, const cv::Mat1f& z_runner, double fB);

/// Depth [m] (NaN / <= 0 = none) as the uint16 values of a KITTI depth PNG (m * 256, 0 = none).
cv::Mat_<uint16_t> kittiDepthValues(const cv::Mat1f& z);

}  // namespace test
}  // namespace lidar_stereo_fusion
