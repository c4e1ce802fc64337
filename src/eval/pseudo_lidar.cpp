// The pseudo-LiDAR sampled from a ground-truth disparity.
#include "lidar_stereo_fusion/eval/pseudo_lidar.h"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace lidar_stereo_fusion {

int scanLineRow(int ring, int num_rows, int image_rows, int first_row) {
  return first_row +
         static_cast<int>(std::floor((ring + 0.5) * (image_rows - first_row) / num_rows));
}

SparseDisparity sampleRowsAsScanLines(const cv::Mat1f& disparity, int num_rows, int first_row) {
  if (first_row < 0 || (first_row > 0 && first_row > disparity.rows - 2)) {
    throw std::invalid_argument("sampleRowsAsScanLines: first_row must be in [0, rows - 2 = " +
                                std::to_string(disparity.rows - 2) + "], got " +
                                std::to_string(first_row));
  }
  const int rows = disparity.rows - first_row;
  if (num_rows < 2 || num_rows > rows) {
    throw std::invalid_argument("sampleRowsAsScanLines: num_rows must be in [2, " +
                                std::to_string(rows) + "], got " + std::to_string(num_rows));
  }
  SparseDisparity sparse;
  sparse.disparity = cv::Mat1f(disparity.size(), 0.f);
  sparse.ring = cv::Mat1s(disparity.size(), static_cast<int16_t>(-1));
  for (int ring = 0; ring < num_rows; ++ring) {
    const int y = scanLineRow(ring, num_rows, disparity.rows, first_row);
    for (int x = 0; x < disparity.cols; ++x) {
      const float d = disparity(y, x);
      if (!(std::isfinite(d) && d > 0.f)) continue;
      sparse.disparity(y, x) = d;
      sparse.ring(y, x) = static_cast<int16_t>(ring);
      ++sparse.points_in_image;
    }
  }
  sparse.points_in_front = sparse.points_in_image;
  return sparse;
}

SparseDisparity shiftToRightView(const SparseDisparity& left) {
  SparseDisparity right;
  right.disparity = cv::Mat1f(left.disparity.size(), 0.f);
  right.ring = cv::Mat1s(left.disparity.size(), static_cast<int16_t>(-1));
  right.points_in_front = left.points_in_front;
  for (int y = 0; y < left.disparity.rows; ++y) {
    for (int x = 0; x < left.disparity.cols; ++x) {
      const float d = left.disparity(y, x);
      if (!(std::isfinite(d) && d > 0.f)) continue;
      const int xr = static_cast<int>(std::floor(x - d + 0.5));
      if (xr < 0 || xr >= left.disparity.cols) continue;
      ++right.points_in_image;
      if (d > right.disparity(y, xr)) {
        right.disparity(y, xr) = d;
        right.ring(y, xr) = left.ring.empty() ? static_cast<int16_t>(-1) : left.ring(y, x);
      }
    }
  }
  return right;
}

}  // namespace lidar_stereo_fusion
