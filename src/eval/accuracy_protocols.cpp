// The Middlebury and KITTI ring hold-out protocols: every method, every layout, every region.
#include "lidar_stereo_fusion/eval/accuracy_protocols.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <ostream>
#include <set>
#include <stdexcept>

#include "lidar_stereo_fusion/core/depth.h"
#include "lidar_stereo_fusion/eval/holdout.h"
#include "lidar_stereo_fusion/eval/pseudo_lidar.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/middlebury.h"

#include "accuracy_common.h"

namespace lidar_stereo_fusion {
namespace {

using namespace accuracy_detail;

const char* const kKittiDrive = "kitti_raw/2011_09_26/2011_09_26_drive_0009_sync";

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

int countRings(const cv::Mat1s& ring) {
  std::set<int> rings;
  for (int y = 0; y < ring.rows; ++y) {
    for (int x = 0; x < ring.cols; ++x) {
      if (ring(y, x) >= 0) rings.insert(ring(y, x));
    }
  }
  return static_cast<int>(rings.size());
}

StereoCamera dummyCamera(const cv::Size& size) {
  StereoCamera camera;
  camera.fx = camera.fy = 1000.0;
  camera.cx = size.width / 2.0;
  camera.cy = size.height / 2.0;
  camera.baseline = 0.1;
  camera.width = size.width;
  camera.height = size.height;
  return camera;
}

/// The search range of the quarter-size Middlebury scenes (ground truth <= 64 px).
FusionParams forMiddlebury(FusionParams params) {
  params.patchmatch.min_disparity = 1.0;
  params.patchmatch.max_disparity = 64.0;
  return params;
}

/// pms of a scene: it does not use the LiDAR, so one run serves every layout.
struct MiddleburyPms {
  cv::Mat1f disparity;
  double seconds = 0;
};

/// Every wanted row on one scene and layout, added to `acc`; the layout's items and rings to
/// `layout`.
void scoreMiddleburyLayout(const MiddleburyScene& scene, const std::string& scene_name,
                           const AccuracyOptions& options,
                           const std::vector<std::pair<std::string, FusionParams>>& rows,
                           const MiddleburyPms& pms, LayoutScores<DisparityMetrics>& layout,
                           LayoutAccumulator<DisparityMetrics>& acc) {
  const StereoCamera camera = dummyCamera(scene.left.size());
  const SparseDisparity left_sparse = middleburyLayout(scene.disparity, layout.name);
  const SparseDisparity right_sparse = shiftToRightView(left_sparse);
  RegionMasks masks = computeRegionMasks(left_sparse, scene.left);
  masks.setInBothViews(scene.disparity);
  layout.items.push_back(scene_name);
  layout.fed_rings.push_back(countRings(left_sparse.ring));
  if (layout.fed_rows.empty()) {
    for (int y = 0; y < left_sparse.disparity.rows; ++y) {
      if (cv::countNonZero(left_sparse.disparity.row(y)) > 0) layout.fed_rows.push_back(y);
    }
  }
  std::vector<std::pair<std::string, cv::Mat1f>> saved;  // saveCase's outputs
  const auto add = [&](const std::string& name, const cv::Mat1f& disparity, double seconds) {
    acc.add(name, scoreRegions(disparity, scene.disparity, masks),
            rawCoverage(disparity, scene.disparity), seconds,
            edgeSides(disparity, scene.disparity, MapKind::kDisparity));
    if (!options.save_dir.empty()) saved.push_back({name, disparity});
  };
  std::map<std::string, cv::Mat1f> results;
  for (const auto& [name, params] : rows) {
    const auto t = Clock::now();
    if (name == "pms") {
      results[name] = pms.disparity;
    } else {
      FusionPipeline pipeline(forMiddlebury(params));
      results[name] =
          pipeline.processSparse(scene.left, scene.right, left_sparse, right_sparse, camera)
              .disparity;
    }
    if (wantedRow(options, name)) {
      add(name, results[name], name == "pms" ? pms.seconds : secondsSince(t));
    }
  }
  if (wantedRow(options, kLidarElsePms)) {
    add(kLidarElsePms, combineMaps(results.at("lidar_bi"), results.at("pms")), 0.0);
  }
  if (wantedRow(options, kNearest)) {
    const auto t = Clock::now();
    const cv::Mat1f nearest = nearestFill(left_sparse.disparity);
    add(kNearest, nearest, secondsSince(t));
  }
  if (wantedRow(options, kIpBasic)) {
    const auto t = Clock::now();
    const cv::Mat1f filled = ipBasicOnDisparity(left_sparse.disparity, camera, options.ip_basic);
    add(kIpBasic, filled, secondsSince(t));
  }
  saveCase(options, layout.name, scene_name, saved, scene.disparity, scene.left);
}

}  // namespace

std::vector<std::string> accuracyMethodNames() {
  return {"fused", "paper", "lidar_bi", "lidar_bf", "pms", kLidarElsePms, kNearest, kIpBasic};
}
std::vector<std::string> middleburyLayoutNames() { return {"mb64", "mb16", "mb42low"}; }
std::vector<std::string> kittiLayoutNames() { return {"ring32", "ring16"}; }
std::vector<std::string> denseLayoutNames() { return {"dense"}; }
std::vector<std::string> syntheticLayoutNames() { return {"syn_exact", "syn_lidar", "syn_image"}; }

std::vector<std::string> accuracyLayoutNames() {
  std::vector<std::string> all;
  for (const auto& names :
       {middleburyLayoutNames(), kittiLayoutNames(), denseLayoutNames(), syntheticLayoutNames()}) {
    all.insert(all.end(), names.begin(), names.end());
  }
  return all;
}

std::string joinedNames(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

void AccuracyOptions::validate() const {
  for (const std::string& m : methods) {
    if (!contains(accuracyMethodNames(), m)) {
      throw std::invalid_argument("AccuracyOptions: unknown method '" + m +
                                  "' (valid: " + joinedNames(accuracyMethodNames()) + ")");
    }
  }
  for (const std::string& l : layouts) {
    if (!contains(accuracyLayoutNames(), l)) {
      throw std::invalid_argument("AccuracyOptions: unknown layout '" + l +
                                  "' (valid: " + joinedNames(accuracyLayoutNames()) + ")");
    }
  }
  if (kitti_frames < 0) throw std::invalid_argument("AccuracyOptions: kitti_frames must be >= 0");
  fused.validate();
  if (paper) paper->validate();
  ip_basic.validate();
}

SparseDisparity middleburyLayout(const cv::Mat1f& ground_truth, const std::string& layout) {
  if (layout == "mb64") return sampleRowsAsScanLines(ground_truth, 64);
  if (layout == "mb16") return sampleRowsAsScanLines(ground_truth, 16);
  if (layout == "mb42low") return sampleRowsAsScanLines(ground_truth, 42, ground_truth.rows / 3);
  throw std::invalid_argument("middleburyLayout: unknown layout '" + layout +
                              "' (valid: mb64, mb16, mb42low)");
}

int kittiKeepEvery(const std::string& layout) {
  if (layout == "ring32") return 2;
  if (layout == "ring16") return 4;
  throw std::invalid_argument("kittiKeepEvery: unknown layout '" + layout +
                              "' (valid: ring32, ring16)");
}

std::vector<LayoutScores<DisparityMetrics>> runMiddleburyProtocol(const AccuracyOptions& options) {
  options.validate();
  std::vector<LayoutScores<DisparityMetrics>> out;
  for (const std::string& l : middleburyLayoutNames()) {
    if (wantedLayout(options, l)) out.emplace_back().name = l;
  }
  const auto rows = pipelineRows(options, true);
  std::vector<LayoutAccumulator<DisparityMetrics>> acc(out.size());
  for (const char* scene_name : {"cones", "teddy"}) {
    const std::string dir =
        (std::filesystem::path(options.data_dir) / "middlebury" / scene_name).string();
    const MiddleburyScene scene = readMiddleburyScene(dir);
    if (options.progress) *options.progress << "Middlebury " << scene_name << std::endl;
    MiddleburyPms pms;
    for (const auto& row : rows) {
      if (row.first != "pms") continue;
      const auto t = Clock::now();
      FusionPipeline pipeline(forMiddlebury(row.second));
      pms.disparity = pipeline
                          .processSparse(scene.left, scene.right, SparseDisparity(),
                                         SparseDisparity(), dummyCamera(scene.left.size()))
                          .disparity;
      pms.seconds = secondsSince(t);
    }
    for (size_t li = 0; li < out.size(); ++li) {
      scoreMiddleburyLayout(scene, scene_name, options, rows, pms, out[li], acc[li]);
    }
  }
  for (size_t li = 0; li < out.size(); ++li) {
    out[li].methods = acc[li].finish();
    const int n = out[li].fed_rings.empty() ? 0 : out[li].fed_rings.front();
    out[li].description = "Middlebury cones + teddy, " + std::to_string(n) +
                          " ground-truth rows as pseudo-LiDAR" +
                          (out[li].name == "mb42low" ? " over the lower 2/3" : "");
  }
  return out;
}

std::vector<LayoutScores<DepthMetrics>> runKittiProtocol(const AccuracyOptions& options) {
  options.validate();
  const std::string drive = (std::filesystem::path(options.data_dir) / kKittiDrive).string();
  if (!std::filesystem::is_directory(drive)) {
    throw std::runtime_error("KITTI drive not found: " + drive);
  }
  const kitti::Calibration calib = kitti::readCalibration(kitti::calibrationDirOf(drive));
  std::vector<kitti::Frame> frames = kitti::listFrames(drive);
  if (options.kitti_frames > 0 && static_cast<int>(frames.size()) > options.kitti_frames) {
    frames.resize(options.kitti_frames);
  }
  std::vector<LayoutScores<DepthMetrics>> out;
  for (const std::string& l : kittiLayoutNames()) {
    if (wantedLayout(options, l)) out.emplace_back().name = l;
  }
  const auto rows = pipelineRows(options, options.kitti_pms);
  std::vector<LayoutAccumulator<DepthMetrics>> acc(out.size());
  std::vector<std::string> notes(out.size());
  for (const kitti::Frame& frame : frames) {
    if (options.progress) *options.progress << "KITTI frame " << frame.name << std::endl;
    const kitti::FrameData data = kitti::loadFrame(frame, calib.camera);
    PmsRun pms;  // no LiDAR: one run serves both layouts
    for (size_t li = 0; li < out.size(); ++li) {
      const HoldoutCase holdout =
          makeRingHoldout(data.cloud, calib.T_cam_velo, calib.camera, options.fused.projection,
                          kittiKeepEvery(out[li].name));
      out[li].items.push_back(frame.name);
      const FedSweep fed = fedSweep(holdout.fed, options, calib);
      out[li].fed_rings.push_back(fed.rings);
      if (!fed.note.empty()) notes[li] = fed.note;
      scoreDepthCase({data, fed.cloud, holdout.reference_depth, calib, out[li].name, frame.name},
                     options, rows, pms, acc[li]);
    }
  }
  for (size_t li = 0; li < out.size(); ++li) {
    out[li].methods = acc[li].finish();
    const int n = out[li].fed_rings.empty() ? 0 : out[li].fed_rings.front();
    out[li].description = "KITTI drive 0009 ring hold-out, " + std::to_string(n) +
                          " rings fed (ring % " + std::to_string(kittiKeepEvery(out[li].name)) +
                          " == 0), the other rings scored, " + std::to_string(frames.size()) +
                          " frames" + notes[li];
  }
  return out;
}

}  // namespace lidar_stereo_fusion
