// The stereo check of a LiDAR-made reference (eval/stereo_check.h).
#include "lidar_stereo_fusion/eval/stereo_check.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace lidar_stereo_fusion {

cv::Ptr<cv::StereoSGBM> referenceSgbm() {
  return cv::StereoSGBM::create(0, 128, 5, 8 * 3 * 25, 32 * 3 * 25, 1, 63, 10, 100, 32,
                                cv::StereoSGBM::MODE_SGBM_3WAY);
}

cv::Mat1f sgbmDisparity(const cv::Mat& left, const cv::Mat& right) {
  cv::Mat fixed_point;  // CV_16S, 4 fractional bits; negative = none
  referenceSgbm()->compute(left, right, fixed_point);
  cv::Mat1f disparity;
  fixed_point.convertTo(disparity, CV_32F, 1.0 / 16.0);
  cv::max(disparity, 0.f, disparity);
  return disparity;
}

StereoCheckCounts removeStereoOutliers(cv::Mat1f& depth, const cv::Mat1f& stereo_disparity,
                                       const StereoCamera& camera, double max_diff_px) {
  camera.validate();
  if (depth.size() != stereo_disparity.size()) {
    throw std::invalid_argument(
        "removeStereoOutliers: the reference and the stereo disparity "
        "differ in size");
  }
  if (!(max_diff_px > 0) || !std::isfinite(max_diff_px)) {
    throw std::invalid_argument("removeStereoOutliers: max_diff_px must be > 0 and finite, got " +
                                std::to_string(max_diff_px));
  }
  const double fb = camera.fx * camera.baseline;
  StereoCheckCounts counts;
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) {
      float& z = depth(y, x);
      if (!(z > 0.f)) continue;
      ++counts.checked;
      const float d = stereo_disparity(y, x);
      if (!(d > 0.f)) {
        ++counts.removed_no_stereo;
        z = 0.f;
      } else if (std::abs(fb / z - d) > max_diff_px) {
        ++counts.removed_disagreeing;
        z = 0.f;
      }
    }
  }
  return counts;
}

}  // namespace lidar_stereo_fusion
