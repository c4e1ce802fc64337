// Scoring, rows and one KITTI case of the accuracy protocols.
#include "accuracy_common.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

#include "lidar_stereo_fusion/core/depth.h"

namespace lidar_stereo_fusion {
namespace accuracy_detail {
namespace {

/// The reference restricted to a region (0 outside it).
cv::Mat1f maskReference(const cv::Mat1f& reference, const cv::Mat1b& mask) {
  if (mask.empty()) return reference;
  cv::Mat1f out(reference.size(), 0.f);
  reference.copyTo(out, mask);
  return out;
}

}  // namespace

const char* const kLidarElsePms = "lidar_bi else pms";
const char* const kNearest = "nearest";
const char* const kIpBasic = "ip_basic";

double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

namespace {

/// Writes `image` to `path` (OpenCV's TIFF writer keeps 32-bit floats exactly).
void writeImage(const std::filesystem::path& path, const cv::Mat& image) {
  bool written = false;
  try {
    written = cv::imwrite(path.string(), image);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("save_dir: cannot write " + path.string() + ": " + e.what());
  }
  if (!written) throw std::runtime_error("save_dir: cannot write " + path.string());
}

}  // namespace

}  // namespace accuracy_detail

void createSaveDir(const std::string& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error || !std::filesystem::is_directory(dir)) {
    throw std::runtime_error("cannot create the folder " + dir +
                             (error ? ": " + error.message() : std::string()));
  }
}

namespace accuracy_detail {

void saveCase(const AccuracyOptions& options, const std::string& layout, const std::string& item,
              const std::vector<std::pair<std::string, cv::Mat1f>>& outputs,
              const cv::Mat1f& reference, const cv::Mat& left) {
  if (options.save_dir.empty()) return;
  createSaveDir(options.save_dir);
  const std::filesystem::path dir(options.save_dir);
  std::string name = item;
  std::replace(name.begin(), name.end(), ' ', '-');
  const std::string stem = layout + "_" + name + "_";
  for (const auto& [method, map] : outputs) {
    std::string file = method;
    std::replace(file.begin(), file.end(), ' ', '_');  // "lidar_bi else pms"
    writeImage(dir / (stem + file + ".tiff"), map);
  }
  writeImage(dir / (stem + "reference.tiff"), reference);
  writeImage(dir / (stem + "left.png"), left);
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

cv::Mat1f ipBasicOnDisparity(const cv::Mat1f& disparity, const StereoCamera& camera,
                             const IpBasicParams& params) {
  return depthToDisparity(ipBasicFill(disparityToDepth(disparity, camera), params), camera);
}

bool wantedRow(const AccuracyOptions& options, const std::string& name) {
  return options.methods.empty() || options.methods.count(name) > 0;
}

bool wantedLayout(const AccuracyOptions& options, const std::string& name) {
  return options.layouts.empty() || options.layouts.count(name) > 0;
}

std::vector<std::pair<std::string, FusionParams>> pipelineRows(const AccuracyOptions& options,
                                                               bool with_pms) {
  std::vector<std::pair<std::string, FusionParams>> rows;
  if (wantedRow(options, "fused")) rows.emplace_back("fused", options.fused);
  if (wantedRow(options, "paper") && options.paper) rows.emplace_back("paper", *options.paper);
  for (Method m : {Method::kLidarBI, Method::kLidarBF, Method::kPlainPMS}) {
    const std::string name = methodName(m);
    const bool needed_for_combination = wantedRow(options, kLidarElsePms) && name != "lidar_bf";
    if (m == Method::kPlainPMS && !with_pms) continue;
    if (!wantedRow(options, name) && !needed_for_combination) continue;
    FusionParams params = options.fused;
    params.method = m;
    rows.emplace_back(name, params);
  }
  return rows;
}

void scoreDepthCase(const DepthCase& c, const AccuracyOptions& options,
                    const std::vector<std::pair<std::string, FusionParams>>& rows, PmsRun& pms,
                    LayoutAccumulator<DepthMetrics>& acc) {
  scoreDepthCaseAgainst(c, {{c.reference, acc, c.layout}}, options, rows, pms);
}

void scoreDepthCaseAgainst(const DepthCase& c, const std::vector<DepthTarget>& targets,
                           const AccuracyOptions& options,
                           const std::vector<std::pair<std::string, FusionParams>>& rows,
                           PmsRun& pms) {
  const StereoCamera& camera = c.calib.camera;
  const FusionInput input{c.frame.left, c.frame.right, c.fed, c.calib.T_cam_velo, camera};
  const SparseDisparity fed =
      projectCloud(c.fed, c.calib.T_cam_velo, camera, options.fused.projection, View::kLeft);
  // Each row's depth and time, in the order the rows are added to the tables.
  std::vector<std::pair<std::string, std::pair<cv::Mat1f, double>>> runs;
  std::map<std::string, cv::Mat1f> depth;
  for (const auto& [name, params] : rows) {
    const auto t = Clock::now();
    if (name == "pms" && !pms.depth.empty()) {
      depth[name] = pms.depth;  // the shared run's time, in every layout (as on Middlebury)
    } else {
      FusionPipeline pipeline(params);
      depth[name] = pipeline.process(input).depth;
      if (name == "pms") pms = {depth[name], secondsSince(t)};
    }
    if (wantedRow(options, name)) {
      runs.push_back({name, {depth[name], name == "pms" ? pms.seconds : secondsSince(t)}});
    }
  }
  if (depth.count("pms") > 0 && wantedRow(options, kLidarElsePms)) {
    runs.push_back({kLidarElsePms, {combineMaps(depth.at("lidar_bi"), depth.at("pms")), 0.0}});
  }
  if (wantedRow(options, kNearest)) {
    const auto t = Clock::now();
    const cv::Mat1f nearest = disparityToDepth(nearestFill(fed.disparity), camera);
    runs.push_back({kNearest, {nearest, secondsSince(t)}});
  }
  if (wantedRow(options, kIpBasic)) {
    const auto t = Clock::now();
    const cv::Mat1f filled = ipBasicFill(disparityToDepth(fed.disparity, camera), options.ip_basic);
    runs.push_back({kIpBasic, {filled, secondsSince(t)}});
  }
  const RegionMasks fed_masks = computeRegionMasks(fed, c.frame.left);
  std::vector<std::pair<std::string, cv::Mat1f>> outputs;
  if (!options.save_dir.empty()) {
    for (const auto& [name, run] : runs) outputs.push_back({name, run.first});
  }
  for (const DepthTarget& target : targets) {
    saveCase(options, target.layout, c.item, outputs, target.reference, c.frame.left);
    RegionMasks masks = fed_masks;
    masks.setDepthBands(target.reference);
    masks.setInBothViews(depthToDisparity(target.reference, camera));
    for (const auto& [name, run] : runs) {
      target.acc.add(name, scoreRegions(run.first, target.reference, masks, camera),
                     rawCoverage(run.first, target.reference), run.second,
                     edgeSides(run.first, target.reference, MapKind::kDepth));
    }
  }
}

int distinctRings(const LidarCloud& cloud) {
  std::set<int> rings;
  for (const LidarPoint& p : cloud) rings.insert(p.ring);
  return static_cast<int>(rings.size());
}

FedSweep fedSweep(const LidarCloud& cloud, const AccuracyOptions& options,
                  const kitti::Calibration& calib) {
  FedSweep out;
  ReorderedSweep sweep =
      reorderSweep(cloud, options.sweep_order, calib.T_cam_velo, calib.camera, 64, 7);
  out.cloud = std::move(sweep.cloud);
  out.rings = distinctRings(out.cloud);
  if (options.sweep_order != SweepOrder::kRecorded) {
    out.note = ", the sweep's order lost (" + sweepOrderName(options.sweep_order) +
               ", its rings recovered by " + ringSourceName(sweep.rings.source) + ")";
  }
  return out;
}

}  // namespace accuracy_detail
}  // namespace lidar_stereo_fusion
