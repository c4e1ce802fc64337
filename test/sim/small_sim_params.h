// A small synthetic camera for tests on hand-made scenes (test/sim, test/eval).
#pragma once

#include "lidar_stereo_fusion/sim/synthetic_frame.h"

namespace lidar_stereo_fusion {
namespace test {

/// 160 x 120 px, fx = fy = 100 px, pixel centres off the horizon row, baseline 0.5 m, exact and
/// noise-free images, a light sweep (0.5 deg between firings: geometry checks need no density).
inline sim::SyntheticParams smallSyntheticParams() {
  sim::SyntheticParams p;
  p.width = 160;
  p.height = 120;
  p.fx = p.fy = 100.0;
  p.cx = 79.5;
  p.cy = 59.5;
  p.baseline = 0.5;
  p.subsamples = 1;
  p.image_noise_sigma = 0.0;
  p.azimuth_step_deg = 0.5;
  return p;
}

}  // namespace test
}  // namespace lidar_stereo_fusion
