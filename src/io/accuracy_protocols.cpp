// The Middlebury and KITTI accuracy protocols: every method, every layout, every region.
#include "lidar_stereo_fusion/io/accuracy_protocols.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <ostream>
#include <set>
#include <stdexcept>

#include "lidar_stereo_fusion/core/depth.h"
#include "lidar_stereo_fusion/io/holdout.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/middlebury.h"

namespace lidar_stereo_fusion {
namespace {

const char* const kKittiDrive = "kitti_raw/2011_09_26/2011_09_26_drive_0009_sync";
const char* const kLidarElsePms = "lidar_bi else pms";
const char* const kNearest = "nearest";

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

/// The reference restricted to a region (0 outside it).
cv::Mat1f maskReference(const cv::Mat1f& reference, const cv::Mat1b& mask) {
  if (mask.empty()) return reference;
  cv::Mat1f out(reference.size(), 0.f);
  reference.copyTo(out, mask);
  return out;
}

double rawCoverage(const cv::Mat1f& estimate, const cv::Mat1f& reference) {
  long covered = 0, total = 0;
  for (int y = 0; y < reference.rows; ++y) {
    for (int x = 0; x < reference.cols; ++x) {
      if (!(reference(y, x) > 0.f)) continue;
      ++total;
      covered += std::isfinite(estimate(y, x)) && estimate(y, x) > 0.f;
    }
  }
  return total > 0 ? static_cast<double>(covered) / total : 0.0;
}

/// Scores of every region: the estimate is filled like the devkit first.
RegionScores<DisparityMetrics> scoreRegions(const cv::Mat1f& disparity, const cv::Mat1f& reference,
                                            const RegionMasks& masks) {
  const cv::Mat1f filled = fillLikeDevkit(disparity, MapKind::kDisparity);
  RegionScores<DisparityMetrics> scores;
  for (int r = 0; r < kRegionCount; ++r) {
    scores[r] = evaluateDisparity(filled, maskReference(reference, masks.mask(Region(r))));
  }
  return scores;
}

RegionScores<DepthMetrics> scoreRegions(const cv::Mat1f& depth, const cv::Mat1f& reference,
                                        const RegionMasks& masks, const StereoCamera& camera) {
  const cv::Mat1f filled = fillLikeDevkit(depth, MapKind::kDepth);
  RegionScores<DepthMetrics> scores;
  for (int r = 0; r < kRegionCount; ++r) {
    scores[r] = evaluateDepth(filled, maskReference(reference, masks.mask(Region(r))), camera);
  }
  return scores;
}

/// Accumulates the rows of one layout in table order.
template <typename Metrics>
class LayoutAccumulator {
 public:
  void add(const std::string& method, const RegionScores<Metrics>& scores, double raw_coverage,
           double seconds) {
    MethodScores<Metrics>& m = get(method);
    m.per_item.push_back(scores);
    m.raw_coverage += raw_coverage;
    m.seconds += seconds;
  }
  /// Means over items, rows in accuracyMethodNames() order.
  std::vector<MethodScores<Metrics>> finish() {
    std::vector<MethodScores<Metrics>> out;
    for (const std::string& name : accuracyMethodNames()) {
      auto it = rows_.find(name);
      if (it == rows_.end()) continue;
      MethodScores<Metrics> m = it->second;
      for (int r = 0; r < kRegionCount; ++r) {
        std::vector<Metrics> items;
        for (const auto& scores : m.per_item) items.push_back(scores[r]);
        m.mean[r] = averageMetrics(items);
      }
      if (!m.per_item.empty()) m.raw_coverage /= m.per_item.size();
      out.push_back(std::move(m));
    }
    return out;
  }

 private:
  MethodScores<Metrics>& get(const std::string& method) {
    MethodScores<Metrics>& m = rows_[method];
    m.name = method;
    return m;
  }
  std::map<std::string, MethodScores<Metrics>> rows_;
};

/// The pipeline rows that run: name -> parameters.
std::vector<std::pair<std::string, FusionParams>> pipelineRows(const AccuracyOptions& options,
                                                               bool with_pms) {
  const auto wanted = [&](const std::string& name) {
    return options.methods.empty() || options.methods.count(name) > 0;
  };
  std::vector<std::pair<std::string, FusionParams>> rows;
  if (wanted("fused")) rows.emplace_back("fused", options.fused);
  if (wanted("paper") && options.paper) rows.emplace_back("paper", *options.paper);
  for (Method m : {Method::kLidarBI, Method::kLidarBF, Method::kPlainPMS}) {
    const std::string name = methodName(m);
    const bool needed_for_combination = wanted(kLidarElsePms) && name != "lidar_bf";
    if (m == Method::kPlainPMS && !with_pms) continue;
    if (!wanted(name) && !needed_for_combination) continue;
    FusionParams params = options.fused;
    params.method = m;
    rows.emplace_back(name, params);
  }
  return rows;
}

bool wantedRow(const AccuracyOptions& options, const std::string& name) {
  return options.methods.empty() || options.methods.count(name) > 0;
}

bool wantedLayout(const AccuracyOptions& options, const std::string& name) {
  return options.layouts.empty() || options.layouts.count(name) > 0;
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

}  // namespace

std::vector<std::string> accuracyMethodNames() {
  return {"fused", "paper", "lidar_bi", "lidar_bf", "pms", kLidarElsePms, kNearest};
}
std::vector<std::string> middleburyLayoutNames() { return {"mb64", "mb16", "mb42low"}; }
std::vector<std::string> kittiLayoutNames() { return {"ring32", "ring16"}; }

void AccuracyOptions::validate() const {
  for (const std::string& m : methods) {
    if (!contains(accuracyMethodNames(), m)) {
      throw std::invalid_argument("AccuracyOptions: unknown method '" + m +
                                  "' (valid: fused, paper, lidar_bi, lidar_bf, pms, "
                                  "lidar_bi else pms, nearest)");
    }
  }
  for (const std::string& l : layouts) {
    if (!contains(middleburyLayoutNames(), l) && !contains(kittiLayoutNames(), l)) {
      throw std::invalid_argument("AccuracyOptions: unknown layout '" + l +
                                  "' (valid: mb64, mb16, mb42low, ring32, ring16)");
    }
  }
  if (kitti_frames < 0) throw std::invalid_argument("AccuracyOptions: kitti_frames must be >= 0");
  fused.validate();
  if (paper) paper->validate();
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
  std::vector<std::string> layouts;
  for (const std::string& l : middleburyLayoutNames()) {
    if (wantedLayout(options, l)) layouts.push_back(l);
  }
  const auto rows = pipelineRows(options, true);
  std::map<std::string, LayoutAccumulator<DisparityMetrics>> acc;
  std::vector<LayoutScores<DisparityMetrics>> out(layouts.size());
  for (const char* scene_name : {"cones", "teddy"}) {
    const std::string dir =
        (std::filesystem::path(options.data_dir) / "middlebury" / scene_name).string();
    const MiddleburyScene scene = readMiddleburyScene(dir);
    const StereoCamera camera = dummyCamera(scene.left.size());
    if (options.progress) *options.progress << "Middlebury " << scene_name << std::endl;
    // pms does not use the LiDAR: one run serves every layout.
    cv::Mat1f pms;
    double pms_seconds = 0;
    for (const auto& [name, params] : rows) {
      if (name != "pms") continue;
      const auto t = Clock::now();
      FusionPipeline pipeline(forMiddlebury(params));
      pms =
          pipeline
              .processSparse(scene.left, scene.right, SparseDisparity(), SparseDisparity(), camera)
              .disparity;
      pms_seconds = secondsSince(t);
    }
    for (size_t li = 0; li < layouts.size(); ++li) {
      LayoutScores<DisparityMetrics>& layout = out[li];
      const SparseDisparity left_sparse = middleburyLayout(scene.disparity, layouts[li]);
      const SparseDisparity right_sparse = shiftToRightView(left_sparse);
      const RegionMasks masks = computeRegionMasks(left_sparse, scene.left);
      layout.name = layouts[li];
      layout.items.push_back(scene_name);
      layout.fed_rings.push_back(countRings(left_sparse.ring));
      if (layout.fed_rows.empty()) {
        for (int y = 0; y < left_sparse.disparity.rows; ++y) {
          if (cv::countNonZero(left_sparse.disparity.row(y)) > 0) layout.fed_rows.push_back(y);
        }
      }
      auto& a = acc[layouts[li]];
      std::map<std::string, cv::Mat1f> results;
      for (const auto& [name, params] : rows) {
        if (name == "pms") {
          results[name] = pms;
          if (wantedRow(options, name)) {
            a.add(name, scoreRegions(pms, scene.disparity, masks),
                  rawCoverage(pms, scene.disparity), pms_seconds);
          }
          continue;
        }
        const auto t = Clock::now();
        FusionPipeline pipeline(forMiddlebury(params));
        results[name] =
            pipeline.processSparse(scene.left, scene.right, left_sparse, right_sparse, camera)
                .disparity;
        if (wantedRow(options, name)) {
          a.add(name, scoreRegions(results[name], scene.disparity, masks),
                rawCoverage(results[name], scene.disparity), secondsSince(t));
        }
      }
      if (wantedRow(options, kLidarElsePms)) {
        const cv::Mat1f combined = combineMaps(results.at("lidar_bi"), results.at("pms"));
        a.add(kLidarElsePms, scoreRegions(combined, scene.disparity, masks),
              rawCoverage(combined, scene.disparity), 0.0);
      }
      if (wantedRow(options, kNearest)) {
        const auto t = Clock::now();
        const cv::Mat1f nearest = nearestFill(left_sparse.disparity);
        a.add(kNearest, scoreRegions(nearest, scene.disparity, masks),
              rawCoverage(nearest, scene.disparity), secondsSince(t));
      }
    }
  }
  for (size_t li = 0; li < layouts.size(); ++li) {
    out[li].methods = acc[layouts[li]].finish();
    const int n = out[li].fed_rings.empty() ? 0 : out[li].fed_rings.front();
    out[li].description = "Middlebury cones + teddy, " + std::to_string(n) +
                          " ground-truth rows as pseudo-LiDAR" +
                          (layouts[li] == "mb42low" ? " over the lower 2/3" : "");
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
  std::vector<std::string> layouts;
  for (const std::string& l : kittiLayoutNames()) {
    if (wantedLayout(options, l)) layouts.push_back(l);
  }
  const auto rows = pipelineRows(options, options.kitti_pms);
  std::map<std::string, LayoutAccumulator<DepthMetrics>> acc;
  std::vector<LayoutScores<DepthMetrics>> out(layouts.size());
  const StereoCamera& camera = calib.camera;
  for (const kitti::Frame& frame : frames) {
    if (options.progress) *options.progress << "KITTI frame " << frame.name << std::endl;
    const kitti::FrameData data = kitti::loadFrame(frame, camera);
    cv::Mat1f pms;  // no LiDAR: one run serves both layouts
    double pms_seconds = 0;
    for (size_t li = 0; li < layouts.size(); ++li) {
      LayoutScores<DepthMetrics>& layout = out[li];
      const HoldoutCase holdout =
          makeRingHoldout(data.cloud, calib.T_cam_velo, camera, options.fused.projection,
                          kittiKeepEvery(layouts[li]));
      const FusionInput input{data.left, data.right, holdout.fed, calib.T_cam_velo, camera};
      const SparseDisparity fed = projectCloud(holdout.fed, calib.T_cam_velo, camera,
                                               options.fused.projection, View::kLeft);
      const RegionMasks masks = computeRegionMasks(fed, data.left);
      const cv::Mat1f& reference = holdout.reference_depth;
      layout.name = layouts[li];
      layout.items.push_back(frame.name);
      std::set<int> rings;
      for (const LidarPoint& p : holdout.fed) rings.insert(p.ring);
      layout.fed_rings.push_back(static_cast<int>(rings.size()));
      auto& a = acc[layouts[li]];
      std::map<std::string, cv::Mat1f> depth;
      for (const auto& [name, params] : rows) {
        const bool reuse = name == "pms" && !pms.empty();
        const auto t = Clock::now();
        if (reuse) {
          depth[name] = pms;
        } else {
          FusionPipeline pipeline(params);
          depth[name] = pipeline.process(input).depth;
        }
        double seconds = secondsSince(t);
        if (name == "pms") {
          if (!reuse) pms_seconds = seconds;
          pms = depth[name];
          seconds = pms_seconds;  // the shared run's time, in every layout (as on Middlebury)
        }
        if (wantedRow(options, name)) {
          a.add(name, scoreRegions(depth[name], reference, masks, camera),
                rawCoverage(depth[name], reference), seconds);
        }
      }
      if (options.kitti_pms && wantedRow(options, kLidarElsePms)) {
        const cv::Mat1f combined = combineMaps(depth.at("lidar_bi"), depth.at("pms"));
        a.add(kLidarElsePms, scoreRegions(combined, reference, masks, camera),
              rawCoverage(combined, reference), 0.0);
      }
      if (wantedRow(options, kNearest)) {
        const auto t = Clock::now();
        const cv::Mat1f nearest = disparityToDepth(nearestFill(fed.disparity), camera);
        a.add(kNearest, scoreRegions(nearest, reference, masks, camera),
              rawCoverage(nearest, reference), secondsSince(t));
      }
    }
  }
  for (size_t li = 0; li < layouts.size(); ++li) {
    out[li].methods = acc[layouts[li]].finish();
    const int n = out[li].fed_rings.empty() ? 0 : out[li].fed_rings.front();
    out[li].description = "KITTI drive 0009 ring hold-out, " + std::to_string(n) +
                          " rings fed (ring % " + std::to_string(kittiKeepEvery(layouts[li])) +
                          " == 0), the other rings scored, " + std::to_string(frames.size()) +
                          " frames";
  }
  return out;
}

}  // namespace lidar_stereo_fusion
