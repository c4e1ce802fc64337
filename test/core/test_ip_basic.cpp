// IP-Basic's fast variant (core/ip_basic.h) on small hand-made depth maps with exact answers: the
// diamond dilation keeps the nearer depth, the small holes close, the extension to the top, a
// constant plane stays constant, a LiDAR-like map of rows fills completely, empty in, empty out.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/ip_basic.h"

namespace lidar_stereo_fusion {
namespace {

/// Every step after the inversion off: kernels 1, no extension, no blur.
IpBasicParams stepsOff() {
  IpBasicParams p;
  p.dilation_kernel = p.closing_kernel = p.hole_fill_kernel = p.large_fill_kernel = 1;
  p.median_kernel = p.blur_kernel = 1;
  p.extrapolate = false;
  p.blur = IpBasicBlur::kNone;
  return p;
}

TEST(IpBasic, DiamondKernelIsTheL1Ball) {
  const cv::Mat k = diamondKernel(5);
  const int expected[5][5] = {
      {0, 0, 1, 0, 0}, {0, 1, 1, 1, 0}, {1, 1, 1, 1, 1}, {0, 1, 1, 1, 0}, {0, 0, 1, 0, 0}};
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 5; ++x) EXPECT_EQ(k.at<uchar>(y, x), expected[y][x]) << x << "," << y;
  }
  EXPECT_EQ(cv::countNonZero(diamondKernel(1)), 1);
  EXPECT_THROW(diamondKernel(4), std::invalid_argument);
}

TEST(IpBasic, ASinglePointIsDilatedByTheDiamond) {
  cv::Mat1f in(9, 9, 0.f);
  in(4, 4) = 20.f;
  IpBasicParams p = stepsOff();
  p.dilation_kernel = 5;
  const cv::Mat1f out = ipBasicFill(in, p);
  for (int y = 0; y < 9; ++y) {
    for (int x = 0; x < 9; ++x) {
      const bool inside = std::abs(x - 4) + std::abs(y - 4) <= 2;
      EXPECT_EQ(out(y, x), inside ? 20.f : 0.f) << x << "," << y;
    }
  }
}

TEST(IpBasic, TheDilationKeepsTheNearerDepth) {
  cv::Mat1f in(5, 8, 0.f);
  in(2, 2) = 10.f;  // near
  in(2, 5) = 40.f;  // far: the two diamonds overlap on columns 3 and 4
  IpBasicParams p = stepsOff();
  p.dilation_kernel = 5;
  const cv::Mat1f out = ipBasicFill(in, p);
  EXPECT_EQ(out(2, 3), 10.f);
  EXPECT_EQ(out(2, 4), 10.f);
  EXPECT_EQ(out(2, 5), 40.f);
  EXPECT_EQ(out(2, 7), 40.f);
}

TEST(IpBasic, TheHoleFillClosesGapsUpToItsKernel) {
  cv::Mat1f in(7, 12, 0.f);
  in(3, 1) = 30.f;
  in(3, 8) = 30.f;  // 6 empty pixels between: a 7x7 kernel reaches 3 to each side
  IpBasicParams p = stepsOff();
  p.hole_fill_kernel = 7;
  const cv::Mat1f out = ipBasicFill(in, p);
  for (int x = 0; x < 12; ++x) EXPECT_EQ(out(3, x), 30.f) << x;
  EXPECT_EQ(out(0, 1), 30.f);  // 3 rows up
  p.hole_fill_kernel = 5;      // reaches 2: columns 4 and 5 stay empty
  const cv::Mat1f small = ipBasicFill(in, p);
  EXPECT_EQ(small(3, 3), 30.f);
  EXPECT_EQ(small(3, 4), 0.f);
  EXPECT_EQ(small(3, 5), 0.f);
  EXPECT_EQ(small(3, 6), 30.f);
}

TEST(IpBasic, TheTopValueOfEveryColumnExtendsToTheTop) {
  cv::Mat1f in(8, 3, 0.f);
  in(5, 0) = 12.f;
  in(6, 0) = 11.f;
  in(2, 1) = 50.f;
  // Column 2 has no value: it stays empty without the large hole fill.
  IpBasicParams p = stepsOff();
  p.extrapolate = true;
  const cv::Mat1f out = ipBasicFill(in, p);
  for (int y = 0; y <= 5; ++y) EXPECT_EQ(out(y, 0), 12.f) << y;
  EXPECT_EQ(out(6, 0), 11.f);
  EXPECT_EQ(out(7, 0), 0.f);  // below the lowest value: not extended
  for (int y = 0; y <= 2; ++y) EXPECT_EQ(out(y, 1), 50.f) << y;
  EXPECT_EQ(cv::countNonZero(out.col(2)), 0);
  // The large hole fill (3x3 here) then fills the empty pixels next to values (nearest wins).
  p.large_fill_kernel = 3;
  const cv::Mat1f filled = ipBasicFill(in, p);
  EXPECT_EQ(filled(0, 2), 50.f);
  EXPECT_EQ(filled(5, 1), 11.f);  // 12 above, 11 below-left: the nearer
  EXPECT_EQ(filled(5, 2), 0.f);   // beyond the kernel's reach
  // Without the extension nothing above is filled.
  EXPECT_EQ(ipBasicFill(in, stepsOff())(0, 0), 0.f);
}

TEST(IpBasic, AConstantPlaneStaysConstantWithEveryBlur) {
  const cv::Mat1f in(20, 30, 25.f);
  for (IpBasicBlur blur : {IpBasicBlur::kGaussian, IpBasicBlur::kBilateral, IpBasicBlur::kNone}) {
    IpBasicParams p;
    p.blur = blur;
    const cv::Mat1f out = ipBasicFill(in, p);
    double lo = 0, hi = 0;
    cv::minMaxLoc(out, &lo, &hi);
    EXPECT_NEAR(lo, 25.0, 1e-5) << static_cast<int>(blur);
    EXPECT_NEAR(hi, 25.0, 1e-5) << static_cast<int>(blur);
  }
}

TEST(IpBasic, ALidarLikeMapOfRowsFillsEveryPixel) {
  // A fronto-parallel plane at 15 m seen on every 4th row from row 6: the default fast variant
  // (closing, fills, extension to the top, median, Gaussian) fills the whole image with 15 m.
  cv::Mat1f in(40, 50, 0.f);
  for (int y = 6; y < 40; y += 4) in.row(y).setTo(15.f);
  const cv::Mat1f out = ipBasicFill(in);
  double lo = 0, hi = 0;
  cv::minMaxLoc(out, &lo, &hi);
  EXPECT_NEAR(lo, 15.0, 1e-5);
  EXPECT_NEAR(hi, 15.0, 1e-5);
}

TEST(IpBasic, EmptyInEmptyOutAndInvalidDepthsAreEmpty) {
  EXPECT_EQ(cv::countNonZero(ipBasicFill(cv::Mat1f(10, 10, 0.f))), 0);
  cv::Mat1f in(10, 10, 0.f);
  in(1, 1) = std::numeric_limits<float>::quiet_NaN();
  in(5, 5) = 150.f;  // beyond max_depth
  in(8, 8) = 0.05f;  // below the paper's 0.1 m
  in(2, 7) = -3.f;
  EXPECT_EQ(cv::countNonZero(ipBasicFill(in)), 0);
  EXPECT_THROW(ipBasicFill(cv::Mat1f()), std::invalid_argument);
  // Parameters refused by validate(), and so by ipBasicFill(): one change to the defaults each.
  const struct {
    const char* what;
    void (*change)(IpBasicParams&);
  } refused[] = {
      {"closing_kernel 4 (even)", [](IpBasicParams& p) { p.closing_kernel = 4; }},
      {"median_kernel 7 (OpenCV's float median: 1, 3 or 5)",
       [](IpBasicParams& p) { p.median_kernel = 7; }},
      {"max_depth 0.1 m", [](IpBasicParams& p) { p.max_depth = 0.1; }},
  };
  for (const auto& c : refused) {
    IpBasicParams p;
    c.change(p);
    EXPECT_THROW(p.validate(), std::invalid_argument) << c.what;
    EXPECT_THROW(ipBasicFill(in, p), std::invalid_argument) << c.what;
  }
}

}  // namespace
}  // namespace lidar_stereo_fusion
