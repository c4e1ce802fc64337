// lsf_demo's pieces (tools/lsf_demo.cpp runs them): one case to run (images, the cloud fed to the
// method and the reference to score against), the methods' results on it, the synthetic and KITTI
// cases (demo_cases.cpp) and the pictures (demo_pictures.cpp).
#pragma once

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/core/metrics.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/sim/synthetic_frame.h"

namespace lsf_demo {

namespace lsf = lidar_stereo_fusion;

constexpr int kFastWidth = 620, kFastHeight = 188;  ///< [px] --fast: half-size images

/// [s] since `start`.
inline double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// One case to run: images, the cloud fed to the method and the reference to score against.
struct DemoCase {
  std::string title;
  lsf::FusionInput input;
  cv::Mat1f reference_depth;  ///< [m], 0 = no value (dense GT or held-out rings)
  bool dense_reference = false;
  /// An extra region scored separately (synthetic: the LiDAR's field of view, the dark van).
  struct Region {
    std::string column;       ///< table column title
    std::string description;  ///< what the region is
    cv::Mat1b mask;           ///< 255 inside
  };
  std::vector<Region> regions;
};

/// One method's result on a case, scored on the whole reference and on each region.
struct MethodRun {
  lsf::Method method;
  lsf::FusionResult result;
  lsf::DepthMetrics all;
  std::vector<lsf::DepthMetrics> regions;  ///< one per DemoCase::regions
};

/// Algorithm 1 on the synthetic frame, scored against the exact visibility flags (printed).
void printOcclusionScore(const lsf::sim::SyntheticFrame& frame);

/// The synthetic street of `p` with its exact depth as the reference; the frame goes to
/// `frame_out` (for printOcclusionScore).
DemoCase syntheticCase(const lsf::sim::SyntheticParams& p, lsf::sim::SyntheticFrame* frame_out);

/// The KITTI sample (`drive_dir`, empty: searched) at `frame` (empty: the first), even rings fed
/// and odd rings as the reference; `fast`: half-size images.
DemoCase kittiCase(const std::string& drive_dir, const std::string& frame, bool fast);

/// Writes the pictures of `runs` on `c` into `out` (created); returns the composite's path.
std::filesystem::path writePictures(const DemoCase& c, const std::vector<MethodRun>& runs,
                                    const std::filesystem::path& out);

}  // namespace lsf_demo
