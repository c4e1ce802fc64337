// Stage 4: disparity -> depth and the coloured point cloud in the left optical frame.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {

/// z = fx * B / d [m]; 0 where d <= 0 or z > max_depth.
cv::Mat1f disparityToDepth(const cv::Mat1f& disparity, const StereoCamera& camera,
                           double max_depth = 0.0 /* 0 = no limit */);

/// depth [m] -> disparity [px]; 0 where depth <= 0 or not finite.
cv::Mat1f depthToDisparity(const cv::Mat1f& depth, const StereoCamera& camera);

struct ColoredPoint {
  float x, y, z;          ///< [m], left optical frame
  uint8_t r, g, b;
};

/// X = (x - cx) z / fx, Y = (y - cy) z / fy, colour from `image` (BGR or grey).
/// Pixels without depth are skipped; `stride` subsamples rows and columns.
std::vector<ColoredPoint> makeColoredCloud(const cv::Mat1f& depth, const cv::Mat& image,
                                           const StereoCamera& camera, int stride = 1);

}  // namespace lidar_stereo_fusion
