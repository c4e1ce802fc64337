// lsf_demo's cases: the synthetic street with exact ground truth (and Algorithm 1 scored against
// the exact visibility), and a KITTI sample frame scored on held-out LiDAR rings.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "demo_case.h"
#include "lidar_stereo_fusion/eval/holdout.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/sim/occlusion_truth.h"

namespace lsf_demo {

namespace fs = std::filesystem;

namespace {

constexpr const char* kKittiDrive = "shared/data/kitti_raw/2011_09_26/2011_09_26_drive_0009_sync";

/// The KITTI sample: the given folder, else searched from the working directory and from the
/// executable's folder upwards (the demo runs from the repo root or from its build folder).
std::string findKittiDrive(const std::string& given) {
  if (!given.empty()) return given;
  std::vector<fs::path> starts = {fs::current_path()};
  char exe[4096];
  const ssize_t n = readlink("/proc/self/exe", exe, sizeof(exe) - 1);
  if (n > 0) starts.push_back(fs::path(std::string(exe, n)).parent_path());
  for (fs::path dir : starts) {
    for (int up = 0; up < 4 && !dir.empty(); ++up, dir = dir.parent_path()) {
      const fs::path candidate = dir.parent_path() / kKittiDrive;
      if (fs::is_directory(candidate)) return candidate.string();
    }
  }
  throw std::runtime_error(std::string("KITTI sample not found (looked for ../") + kKittiDrive +
                           " from here and from the executable); pass --kitti DRIVE_DIR");
}

/// Halves images and intrinsics (pixel centres kept).
void halveCase(lsf::FusionInput& in) {
  cv::resize(in.left, in.left, cv::Size(kFastWidth, kFastHeight), 0, 0, cv::INTER_AREA);
  cv::resize(in.right, in.right, cv::Size(kFastWidth, kFastHeight), 0, 0, cv::INTER_AREA);
  lsf::StereoCamera& cam = in.camera;
  const double sx = static_cast<double>(kFastWidth) / cam.width;
  const double sy = static_cast<double>(kFastHeight) / cam.height;
  cam.fx *= sx;
  cam.fy *= sy;
  cam.cx = (cam.cx + 0.5) * sx - 0.5;
  cam.cy = (cam.cy + 0.5) * sy - 0.5;
  cam.width = kFastWidth;
  cam.height = kFastHeight;
}

}  // namespace

void printOcclusionScore(const lsf::sim::SyntheticFrame& frame) {
  const lsf::FusionParams params;
  const lsf::SparseDisparity sparse =
      lsf::projectCloud(frame.cloud, frame.T_cam_lidar, frame.camera, params.projection);
  const lsf::ScanLines before = lsf::completeScanLines(sparse, params.bi);
  lsf::ScanLines after{before.disparity.clone(), before.ring.clone()};
  lsf::removeOccludedPoints(after, frame.left, params.bi);
  const lsf::sim::OcclusionRemovalScore s = lsf::sim::scoreOcclusionRemoval(frame, before, after);
  std::printf(
      "Algorithm 1 vs exact visibility: removed %d of %d LiDAR points the camera cannot "
      "see (%.0f%%), kept %d of %d visible ones (%.1f%%)\n",
      s.occluded_removed, s.occluded, 100 * s.removedFraction(), s.visible_kept, s.visible,
      100 * s.keptFraction());
}

DemoCase syntheticCase(const lsf::sim::SyntheticParams& p, lsf::sim::SyntheticFrame* frame_out) {
  const auto start = std::chrono::steady_clock::now();
  lsf::sim::SyntheticFrame frame = lsf::sim::generateStreetFrame(p, 0);
  int in_image = 0, hidden = 0;
  for (const lsf::sim::PointTruth& t : frame.truth) {
    in_image += t.in_image ? 1 : 0;
    hidden += (t.in_image && !t.visible) ? 1 : 0;
  }
  std::printf(
      "Synthetic street (seed %llu, %dx%d, %d rings): generated in %.1f s; %zu LiDAR "
      "points, %d in the left image, %d of them hidden from the left camera\n",
      static_cast<unsigned long long>(p.seed), p.width, p.height, p.rings, secondsSince(start),
      frame.cloud.size(), in_image, hidden);
  DemoCase c;
  c.title = "Synthetic street, exact ground truth";
  c.input.left = frame.left;
  c.input.right = frame.right;
  c.input.cloud = frame.cloud;
  c.input.T_cam_lidar = frame.T_cam_lidar;
  c.input.camera = frame.camera;
  c.reference_depth = frame.depth;
  c.dense_reference = true;
  c.regions = {
      {"fov MAE", "the LiDAR's vertical field of view (where KITTI has ground truth)",
       frame.lidar_fov},
      {"van MAE", "the dark untextured van (stereo alone fails there)", frame.low_texture}};
  *frame_out = std::move(frame);
  return c;
}

DemoCase kittiCase(const std::string& drive_dir, const std::string& frame, bool fast) {
  const std::string drive = findKittiDrive(drive_dir);
  const lsf::kitti::Calibration calib =
      lsf::kitti::readCalibration(lsf::kitti::calibrationDirOf(drive));
  const std::vector<lsf::kitti::Frame> frames = lsf::kitti::listFrames(drive);
  if (frames.empty()) throw std::runtime_error("no complete frame in " + drive);
  auto it = frames.begin();
  if (!frame.empty()) {
    it = std::find_if(frames.begin(), frames.end(),
                      [&](const lsf::kitti::Frame& f) { return f.name == frame; });
    if (it == frames.end()) throw std::runtime_error("no frame " + frame + " in " + drive);
  }
  const lsf::kitti::FrameData data = lsf::kitti::loadFrame(*it, calib.camera);
  DemoCase c;
  c.title = "KITTI " + fs::path(drive).filename().string() + " frame " + it->name +
            ": even rings in, odd rings as reference";
  c.input.left = data.left;
  c.input.right = data.right;
  c.input.T_cam_lidar = calib.T_cam_velo;
  c.input.camera = calib.camera;
  if (fast) halveCase(c.input);
  const lsf::HoldoutCase holdout = lsf::makeRingHoldout(
      data.cloud, calib.T_cam_velo, c.input.camera, lsf::FusionParams().projection);
  c.input.cloud = holdout.fed;
  c.reference_depth = holdout.reference_depth;
  std::printf("KITTI %s frame %s (%dx%d): %zu points, %zu fed (even rings), %d reference pixels\n",
              drive.c_str(), it->name.c_str(), c.input.camera.width, c.input.camera.height,
              data.cloud.size(), holdout.fed.size(), cv::countNonZero(holdout.reference_depth));
  return c;
}

}  // namespace lsf_demo
