// IP-Basic, a LiDAR-only baseline: Ku, Harakeh, Waslander, "In Defense of Classical Image
// Processing: Fast Depth Completion on the CPU", CRV 2018, its "fast" variant (Section III,
// Fig. 2): morphology and blurs on the inverted depth map. Not part of the fused method; the
// accuracy protocols (eval/accuracy_protocols.h) run it beside the other LiDAR-only rows.
//
// The steps, in the paper's order (ipBasicFill):
//  1. inversion: D_inv = max_depth - D on the pixels with a value, so that dilation (a maximum)
//     keeps the NEARER depth and empty pixels (0) lose to every value;
//  2. dilation with a 5x5 diamond kernel;
//  3. small hole closure: morphological closing with a full 5x5 kernel;
//  4. small hole fill: empty pixels take a full 7x7 dilation;
//  5. extension to the top of the frame: in every column the pixels above the top value take it;
//     then large hole fill: empty pixels take a full 31x31 dilation;
//  6. 5x5 median blur, then a 5x5 Gaussian blur (applied only where there is a value) or a
//     bilateral filter;
//  7. re-inversion: D = max_depth - D_inv where D_inv has a value.
// A pixel "has a value" in the inverted map when D_inv > 0.1 m (the paper's code's test).
//
// Where this differs from the paper (and its code, kujason/ip_basic fill_in_fast): input depths
// outside (0.1, max_depth - 0.1) m are treated as empty (the code inverts a depth beyond
// max_depth to a negative value that survives to the output); NaN / inf are empty. Each kernel can
// be set to 1 (the step does nothing) and the blur to kNone, for tests and ablations.
#pragma once

#include <opencv2/core.hpp>

namespace lidar_stereo_fusion {

/// The blur of step 6 after the median.
enum class IpBasicBlur {
  kGaussian,   ///< the paper's result (its code's blur_type 'gaussian'): lower RMSE
  kBilateral,  ///< its code's recommended 'bilateral': keeps local structure
  kNone,       ///< no blur after the median
};

struct IpBasicParams {
  double max_depth = 100.0;    ///< [m] inversion offset; depths >= max_depth - 0.1 are empty
  int dilation_kernel = 5;     ///< [px] side of the diamond of step 2 (odd)
  int closing_kernel = 5;      ///< [px] full kernel of step 3 (odd)
  int hole_fill_kernel = 7;    ///< [px] full kernel of step 4 (odd)
  bool extrapolate = true;     ///< step 5 (the paper's result uses it)
  int large_fill_kernel = 31;  ///< [px] full kernel of step 5's large hole fill (odd)
  int median_kernel = 5;       ///< [px] 1, 3 or 5 (OpenCV's float median)
  IpBasicBlur blur = IpBasicBlur::kGaussian;
  int blur_kernel = 5;                 ///< [px] Gaussian / bilateral diameter (odd)
  double bilateral_sigma_depth = 1.5;  ///< [m] bilateral range sigma
  double bilateral_sigma_space = 2.0;  ///< [px] bilateral spatial sigma
  /// Throws std::invalid_argument naming the first impossible value.
  void validate() const;
};

/// The diamond (L1 ball) kernel of odd side `size` (CV_8U, 1 inside): 5 -> the paper's 5x5
/// diamond (13 ones). Throws std::invalid_argument for an even or non-positive size.
cv::Mat diamondKernel(int size);

/// Completes a sparse depth map [m] (0 / NaN = empty) by IP-Basic's fast variant (see the file
/// comment); returns depth [m] of the same size, 0 where it stays empty. Empty in, empty out.
/// Throws std::invalid_argument on an empty map or invalid params.
cv::Mat1f ipBasicFill(const cv::Mat1f& depth, const IpBasicParams& params = {});

}  // namespace lidar_stereo_fusion
