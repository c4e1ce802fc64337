// A pseudo-LiDAR sampled from a ground-truth disparity (the Middlebury protocols of
// eval/accuracy_protocols.h): evenly spaced rows as scan lines, in the left and the right view.
// ROS-free.
#pragma once

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/lidar_projection.h"

namespace lidar_stereo_fusion {

/// Pseudo-LiDAR: `num_rows` evenly spaced rows of `disparity` from `first_row` down: the row of
/// ring i is first_row + floor((i + 0.5) * (rows - first_row) / num_rows), ring 0 at the top
/// (first_row = 0: the whole image). Every pixel of those rows where the ground truth is > 0
/// becomes a sample of that ring. points_in_front / points_in_image count the samples. Throws
/// std::invalid_argument when first_row is not in [0, rows - 2] or num_rows is not in
/// [2, rows - first_row].
SparseDisparity sampleRowsAsScanLines(const cv::Mat1f& disparity, int num_rows, int first_row = 0);

/// The image row [px] of `ring` in sampleRowsAsScanLines's layout (no checks).
int scanLineRow(int ring, int num_rows, int image_rows, int first_row = 0);

/// The same samples seen from the right view: the sample at (x, y) with disparity d moves to
/// column floor(x - d + 0.5) (as projectCloud's right view does), keeps d and its ring; the larger
/// disparity wins a pixel; samples leaving the image are dropped.
SparseDisparity shiftToRightView(const SparseDisparity& left);

}  // namespace lidar_stereo_fusion
