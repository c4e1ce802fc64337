// IP-Basic's fast depth completion (Ku et al., CRV 2018) on the inverted depth map.
#include "lidar_stereo_fusion/core/ip_basic.h"

#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

namespace lidar_stereo_fusion {
namespace {

/// An inverted pixel has a value above this [m] (the paper's code's threshold).
constexpr float kEmptyBelow = 0.1f;

void requireOddKernel(int size, const char* name) {
  if (size < 1 || size % 2 == 0) {
    throw std::invalid_argument(std::string("IpBasicParams: ") + name +
                                " must be odd and >= 1, got " + std::to_string(size));
  }
}

cv::Mat fullKernel(int size) { return cv::Mat::ones(size, size, CV_8U); }

/// Steps 4 and 5's fill: pixels without a value take the dilation of the map by `kernel`.
void fillEmptyByDilation(cv::Mat1f& inverted, const cv::Mat& kernel) {
  cv::Mat1f dilated;
  cv::dilate(inverted, dilated, kernel);
  dilated.copyTo(inverted, inverted < kEmptyBelow);
}

/// Step 5, first half: in every column the pixels above the topmost value take it.
void extendToTop(cv::Mat1f& inverted) {
  for (int x = 0; x < inverted.cols; ++x) {
    int top = 0;
    while (top < inverted.rows && !(inverted(top, x) > kEmptyBelow)) ++top;
    if (top == inverted.rows) continue;  // a column without any value stays as it is
    for (int y = 0; y < top; ++y) inverted(y, x) = inverted(top, x);
  }
}

/// Step 6.
void blur(cv::Mat1f& inverted, const IpBasicParams& params) {
  if (params.median_kernel > 1) cv::medianBlur(inverted.clone(), inverted, params.median_kernel);
  if (params.blur_kernel <= 1) return;
  if (params.blur == IpBasicBlur::kGaussian) {
    // Only where there is a value (the paper's code): empty pixels stay empty.
    cv::Mat1f blurred;
    cv::GaussianBlur(inverted, blurred, {params.blur_kernel, params.blur_kernel}, 0);
    blurred.copyTo(inverted, inverted > kEmptyBelow);
  } else if (params.blur == IpBasicBlur::kBilateral) {
    cv::Mat1f filtered;
    cv::bilateralFilter(inverted, filtered, params.blur_kernel, params.bilateral_sigma_depth,
                        params.bilateral_sigma_space);
    inverted = filtered;
  }
}

}  // namespace

void IpBasicParams::validate() const {
  if (!std::isfinite(max_depth) || max_depth <= 2 * kEmptyBelow) {
    throw std::invalid_argument("IpBasicParams: max_depth must be finite and > 0.2 m, got " +
                                std::to_string(max_depth));
  }
  requireOddKernel(dilation_kernel, "dilation_kernel");
  requireOddKernel(closing_kernel, "closing_kernel");
  requireOddKernel(hole_fill_kernel, "hole_fill_kernel");
  requireOddKernel(large_fill_kernel, "large_fill_kernel");
  requireOddKernel(blur_kernel, "blur_kernel");
  if (median_kernel != 1 && median_kernel != 3 && median_kernel != 5) {
    throw std::invalid_argument(
        "IpBasicParams: median_kernel must be 1, 3 or 5 (OpenCV's float median), got " +
        std::to_string(median_kernel));
  }
  if (!(bilateral_sigma_depth > 0) || !(bilateral_sigma_space > 0)) {
    throw std::invalid_argument("IpBasicParams: the bilateral sigmas must be > 0");
  }
}

cv::Mat diamondKernel(int size) {
  if (size < 1 || size % 2 == 0) {
    throw std::invalid_argument("diamondKernel: size must be odd and >= 1, got " +
                                std::to_string(size));
  }
  const int r = size / 2;
  cv::Mat kernel(size, size, CV_8U, cv::Scalar(0));
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) kernel.at<uchar>(y, x) = std::abs(x - r) + std::abs(y - r) <= r;
  }
  return kernel;
}

cv::Mat1f ipBasicFill(const cv::Mat1f& depth, const IpBasicParams& params) {
  if (depth.empty()) throw std::invalid_argument("ipBasicFill: empty depth map");
  params.validate();
  const float max_depth = static_cast<float>(params.max_depth);
  // Step 1: inversion (NaN fails both comparisons and stays empty).
  cv::Mat1f inverted(depth.size(), 0.f);
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) {
      const float d = depth(y, x);
      if (d > kEmptyBelow && d < max_depth - kEmptyBelow) inverted(y, x) = max_depth - d;
    }
  }
  // Steps 2-4: diamond dilation, small hole closure and fill.
  cv::dilate(inverted.clone(), inverted, diamondKernel(params.dilation_kernel));
  cv::morphologyEx(inverted.clone(), inverted, cv::MORPH_CLOSE, fullKernel(params.closing_kernel));
  fillEmptyByDilation(inverted, fullKernel(params.hole_fill_kernel));
  // Step 5: extension to the top, large hole fill.
  if (params.extrapolate) {
    extendToTop(inverted);
    fillEmptyByDilation(inverted, fullKernel(params.large_fill_kernel));
  }
  blur(inverted, params);
  // Step 7: re-inversion.
  cv::Mat1f out(depth.size(), 0.f);
  for (int y = 0; y < out.rows; ++y) {
    for (int x = 0; x < out.cols; ++x) {
      if (inverted(y, x) > kEmptyBelow) out(y, x) = max_depth - inverted(y, x);
    }
  }
  return out;
}

}  // namespace lidar_stereo_fusion
