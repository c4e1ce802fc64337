// Hand-made maps for the up-sampling tests (test_upsampling.cpp, test_upsampling_dense.cpp):
// sparse LiDAR disparity and scan lines with rings, and uniform images.
#pragma once

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/upsampling.h"

namespace lidar_stereo_fusion {
namespace test {

/// A rows x cols sparse map without points (disparity 0, ring -1).
inline SparseDisparity emptySparse(int rows, int cols) {
  SparseDisparity s;
  s.disparity = cv::Mat1f::zeros(rows, cols);
  s.ring = cv::Mat1s(rows, cols, static_cast<short>(-1));
  return s;
}

/// A point at column x, row y with disparity d [px] on `ring`.
inline void addPoint(SparseDisparity& s, int x, int y, float d, short ring) {
  s.disparity(y, x) = d;
  s.ring(y, x) = ring;
}

/// rows x cols scan lines without a line (disparity 0, ring -1).
inline ScanLines emptyLines(int rows, int cols) {
  ScanLines l;
  l.disparity = cv::Mat1f::zeros(rows, cols);
  l.ring = cv::Mat1s(rows, cols, static_cast<short>(-1));
  return l;
}

/// A full-width scan line at `row` with disparity d.
inline void addLine(ScanLines& l, int row, float d, short ring) {
  l.disparity.row(row).setTo(d);
  l.ring.row(row).setTo(ring);
}

/// A BGR image of one colour.
inline cv::Mat uniformImage(int rows, int cols, cv::Vec3b color = {100, 100, 100}) {
  return cv::Mat(rows, cols, CV_8UC3, cv::Scalar(color[0], color[1], color[2]));
}

}  // namespace test
}  // namespace lidar_stereo_fusion
