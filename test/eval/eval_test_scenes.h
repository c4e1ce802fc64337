// Small synthetic inputs shared by the eval tests: a pinhole stereo camera and a textured pair
// with a known disparity.
#pragma once

#include <opencv2/core.hpp>

#include "core/test_scenes.h"
#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {
namespace test {

/// A w x h camera with the principal point in the middle; fx * baseline = 50 px m (z = 10 m is
/// 5 px, 25 m is 2 px).
inline StereoCamera camera(int w, int h) { return centredCamera(w, h, 100.0); }

/// Random texture (fixed seed): the right image is the left shifted by `shift` px (a
/// fronto-parallel plane at disparity `shift`), 0 where the left has no match.
inline void shiftedTexture(int w, int h, int shift, cv::Mat1b& left, cv::Mat1b& right) {
  left.create(h, w);
  cv::RNG rng(7);
  rng.fill(left, cv::RNG::UNIFORM, 0, 256);
  right = cv::Mat1b::zeros(h, w);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x + shift < w; ++x) right(y, x) = left(y, x + shift);
  }
}

}  // namespace test
}  // namespace lidar_stereo_fusion
