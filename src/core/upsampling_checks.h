// The input check shared by the stage-2 up-sampling files (upsampling.cpp: BI* and the search
// bounds; upsampling_bf.cpp: BF*). Private to the core.
#pragma once

#include <stdexcept>
#include <string>

#include <opencv2/core.hpp>

namespace lidar_stereo_fusion {

/// Throws std::invalid_argument naming `where` when the disparity map is empty.
inline void requireDisparityMap(const cv::Mat1f& map, const char* where) {
  if (map.empty()) throw std::invalid_argument(std::string(where) + ": disparity map is empty");
}

}  // namespace lidar_stereo_fusion
