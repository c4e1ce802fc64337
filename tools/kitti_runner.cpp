// kitti_runner: runs the fusion on every frame of a KITTI raw drive and writes KITTI
// depth-completion PNGs; optionally scores them against reference depth PNGs or a ring hold-out.
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "lidar_stereo_fusion/core/metrics.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/io/cli.h"
#include "lidar_stereo_fusion/io/holdout.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/params_yaml.h"
#include "lidar_stereo_fusion/io/pcd.h"
#include "lidar_stereo_fusion/io/report.h"
#include "lidar_stereo_fusion/io/visualization.h"

namespace lsf = lidar_stereo_fusion;
namespace fs = std::filesystem;

namespace {

const char* const kUsage = R"(Usage: kitti_runner --kitti-raw <drive_sync_dir> --out <dir> [options]

Runs LiDAR-stereo fusion on every frame of a KITTI raw drive that has image_02, image_03 and a
velodyne_points .bin, and writes <out>/<frame>.png in the KITTI depth-completion format (uint16,
metres * 256, 0 = no value, the size of image_02). Calibration is read from the drive's parent
folder (calib_cam_to_cam.txt, calib_velo_to_cam.txt).

Options:
  --kitti-raw <dir>    the drive, e.g. .../2011_09_26/2011_09_26_drive_0009_sync
  --out <dir>          output folder (created)
  --method <name>      fused_bi (default; the paper: --params config/paper.yaml) | fused_bf | pms | lidar_bi | lidar_bf
  --params <yaml>      parameters (see config/*.yaml); --method overrides its 'method'
  --reference <dir>    score against KITTI depth PNGs <dir>/<frame>.png (frames without one are
                       not scored): MAE, RMSE [mm], iMAE, iRMSE [1/km], disparity >2/3/5 px
  --holdout even|none  even: feed the even LiDAR rings only and score against the odd rings'
                       depth (a ground-truth-free accuracy check; excludes --reference)
  --save-vis           also write <out>/vis/<frame>_{sparse,prior,confidence,disparity,depth,
                       error}.png, each with a colour bar in its unit (depth in metres,
                       disparity and error in px, confidence 0 .. 1)
  --save-pcd           also write <out>/<frame>.pcd: the coloured points of the depth (those of
                       the node's points2: every pixel with depth, back-projected into the left
                       optical frame [m], in row-major order), with PCL's writer: fields x y z
                       rgb, DATA binary_compressed (pcl_viewer, CloudCompare, PCL's converters)
  --frames N           process only the first N frames
  --help               this text

Frames with image_02 but without image_03 or the .bin are named and skipped; a frame that fails
(corrupt .bin or image, ...) is named and the run goes on with the next one.

Exit status: 0 on success, 1 when any frame failed or on missing or corrupt input (calibration,
drive, parameters, unwritable output folder), 2 on a bad command line.
)";

struct Options {
  std::string drive, out, params, reference, holdout = "none";
  std::optional<std::string> method;
  bool save_vis = false;
  bool save_pcd = false;
  int frames = 0;  // 0 = all
};

Options parseOptions(int argc, char** argv) {
  const lsf::CommandLine cl(
      argc, argv,
      {"--kitti-raw", "--out", "--method", "--params", "--reference", "--frames", "--holdout"},
      {"--save-vis", "--save-pcd", "--help"});
  Options o;
  if (cl.has("--help")) return o;
  o.drive = cl.value("--kitti-raw");
  o.out = cl.value("--out");
  if (o.drive.empty()) throw lsf::UsageError("--kitti-raw is required");
  if (o.out.empty()) throw lsf::UsageError("--out is required");
  if (cl.has("--method")) {
    o.method = cl.choice("--method", "", {"fused_bi", "fused_bf", "pms", "lidar_bi", "lidar_bf"});
  }
  o.params = cl.value("--params");
  o.reference = cl.value("--reference");
  o.holdout = cl.choice("--holdout", "none", {"even", "none"});
  if (o.holdout == "even" && !o.reference.empty()) {
    throw lsf::UsageError("--holdout even and --reference exclude each other");
  }
  o.save_vis = cl.has("--save-vis");
  o.save_pcd = cl.has("--save-pcd");
  o.frames = cl.intValue("--frames", 0, 1, 1000000);
  return o;
}

lsf::FusionParams loadParams(const Options& o) {
  lsf::FusionParams params;
  if (!o.params.empty()) lsf::loadParamsYaml(o.params, params);
  if (o.method) params.method = lsf::parseMethod(*o.method);
  params.validate();
  return params;
}

void createDirectory(const fs::path& dir) {
  std::error_code error;
  fs::create_directories(dir, error);
  if (error || !fs::is_directory(dir)) {
    throw std::runtime_error("cannot create output folder " + dir.string() + ": " +
                             error.message());
  }
}

void writeImage(const fs::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image)) throw std::runtime_error("cannot write " + path.string());
}

/// The reference of one frame: the odd rings (hold-out), <reference>/<frame>.png, or none.
std::optional<cv::Mat1f> referenceOf(const Options& o, const lsf::kitti::Frame& frame,
                                     const lsf::StereoCamera& camera) {
  if (o.reference.empty()) return std::nullopt;
  const fs::path path = fs::path(o.reference) / (frame.name + ".png");
  if (!fs::exists(path)) return std::nullopt;
  cv::Mat1f reference = lsf::kitti::readDepthPng(path.string());
  if (reference.cols != camera.width || reference.rows != camera.height) {
    throw std::runtime_error("reference " + path.string() + " is " +
                             std::to_string(reference.cols) + "x" + std::to_string(reference.rows) +
                             ", the images are " + std::to_string(camera.width) + "x" +
                             std::to_string(camera.height));
  }
  return reference;
}

void saveVisualisation(const fs::path& dir, const std::string& name, const cv::Mat& left,
                       const lsf::FusionResult& result, const std::optional<cv::Mat1f>& reference,
                       const lsf::StereoCamera& camera) {
  double max_disparity = 0;
  cv::minMaxLoc(result.sparse.disparity, nullptr, &max_disparity);
  writeImage(dir / (name + "_sparse.png"),
             lsf::withColorBar(lsf::overlaySparse(left, result.sparse.disparity, max_disparity), 0,
                               max_disparity, "px disparity"));
  if (!result.prior.empty()) {
    writeImage(dir / (name + "_prior.png"),
               lsf::withColorBar(lsf::colorizeDisparity(result.prior, max_disparity), 0,
                                 max_disparity, "px disparity"));
    writeImage(dir / (name + "_confidence.png"),
               lsf::withColorBar(lsf::colorizeConfidence(result.confidence, result.prior), 0, 1,
                                 "confidence", cv::COLORMAP_VIRIDIS));
  }
  writeImage(dir / (name + "_disparity.png"),
             lsf::withColorBar(lsf::colorizeDisparity(result.disparity, max_disparity), 0,
                               max_disparity, "px disparity"));
  constexpr double kMaxDepth = 80.0;  ///< [m] colorizeDepth's scale
  writeImage(dir / (name + "_depth.png"),
             lsf::withColorBar(lsf::colorizeDepth(result.depth, kMaxDepth), kMaxDepth, 0, "m"));
  if (reference) {
    constexpr double kMaxError = 5.0;  ///< [px] colorizeError's scale
    writeImage(
        dir / (name + "_error.png"),
        lsf::withColorBar(lsf::colorizeError(result.disparity,
                                             lsf::depthToDisparity(*reference, camera), kMaxError),
                          0, kMaxError, "px error"));
  }
}

/// Fails now, with the reason, when `dir` cannot take files (not after the first frame).
void requireWritable(const fs::path& dir) {
  const fs::path probe = dir / (".kitti_runner_probe_" + std::to_string(::getpid()));
  FILE* file = std::fopen(probe.string().c_str(), "wb");
  if (file == nullptr) {
    throw std::runtime_error("cannot write into output folder " + dir.string() + ": " +
                             std::strerror(errno));
  }
  std::fclose(file);
  fs::remove(probe);
}

/// Runs one frame and writes its outputs; throws std::runtime_error naming the problem.
void runFrame(const Options& o, const lsf::kitti::Frame& frame,
              const lsf::kitti::Calibration& calib, const lsf::FusionParams& params,
              lsf::FusionPipeline& pipeline, std::vector<lsf::DepthRow>& rows,
              std::vector<lsf::DepthMetrics>& scores, std::vector<lsf::FrameStats>& stats) {
  lsf::kitti::FrameData data = lsf::kitti::loadFrame(frame, calib.camera);
  if (!data.rings.plausible) {
    std::cerr << "\nkitti_runner: warning: frame " << frame.name << ": rings of " << frame.velodyne
              << " are implausible (" << data.rings.fallbacks << "); using "
              << lsf::ringSourceName(data.rings.source) << " (" << data.rings.rings << " rings)\n";
  }
  lsf::FusionInput input{data.left, data.right, {}, calib.T_cam_velo, calib.camera};
  std::optional<cv::Mat1f> reference;
  if (o.holdout == "even") {
    lsf::HoldoutCase holdout =
        lsf::makeRingHoldout(data.cloud, calib.T_cam_velo, calib.camera, params.projection);
    input.cloud = std::move(holdout.fed);
    reference = holdout.reference_depth;
  } else {
    input.cloud = std::move(data.cloud);
    reference = referenceOf(o, frame, calib.camera);
  }
  lsf::FusionResult result;
  try {
    result = pipeline.process(input);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(e.what());
  }
  if (result.stats.points_in_front == 0) {
    throw std::runtime_error("no LiDAR point in front of the camera in " + frame.velodyne +
                             " (check the sweep and calib_velo_to_cam.txt)");
  }
  lsf::kitti::writeDepthPng((fs::path(o.out) / (frame.name + ".png")).string(), result.depth);
  if (o.save_pcd) {
    lsf::pcd::writeColoredPcd((fs::path(o.out) / (frame.name + ".pcd")).string(),
                              lsf::makeColoredCloud(result.depth, data.left, calib.camera));
  }
  if (reference) {
    scores.push_back(lsf::evaluateDepth(result.depth, *reference, calib.camera));
    rows.push_back({frame.name, scores.back()});
  }
  if (o.save_vis) {
    saveVisualisation(fs::path(o.out) / "vis", frame.name, data.left, result, reference,
                      calib.camera);
  }
  stats.push_back(result.stats);
}

int run(const Options& o) {
  const lsf::FusionParams params = loadParams(o);
  // The drive first: a wrong --kitti-raw must be named as such, not as a missing calibration.
  std::vector<std::string> incomplete;
  std::vector<lsf::kitti::Frame> frames = lsf::kitti::listFrames(o.drive, &incomplete);
  const lsf::kitti::Calibration calib =
      lsf::kitti::readCalibration(lsf::kitti::calibrationDirOf(o.drive));
  for (const std::string& line : incomplete) {
    std::cerr << "kitti_runner: warning: skipped " << line << "\n";
  }
  if (frames.empty()) {
    throw std::runtime_error("no frame in " + o.drive +
                             " has image_02, image_03 and a velodyne_points .bin");
  }
  if (o.frames > 0 && static_cast<size_t>(o.frames) < frames.size()) frames.resize(o.frames);
  createDirectory(o.out);
  requireWritable(o.out);
  if (o.save_vis) createDirectory(fs::path(o.out) / "vis");

  std::cerr << "kitti_runner: " << frames.size() << " frames, method "
            << lsf::methodName(params.method)
            << (o.holdout == "even" ? ", hold-out: even rings in, odd rings scored" : "") << "\n";
  lsf::FusionPipeline pipeline(params);
  std::vector<lsf::DepthRow> rows;
  std::vector<lsf::DepthMetrics> scores;
  std::vector<lsf::FrameStats> stats;
  std::vector<std::string> failed;
  lsf::ProgressBar progress(std::cerr, static_cast<int>(frames.size()), ::isatty(2) != 0);
  for (size_t i = 0; i < frames.size(); ++i) {
    progress.update(static_cast<int>(i), frames[i].name);
    try {
      runFrame(o, frames[i], calib, params, pipeline, rows, scores, stats);
    } catch (const std::exception& e) {  // name it and go on with the next frame
      failed.push_back(frames[i].name);
      std::cerr << "\nkitti_runner: error: frame " << frames[i].name << " failed: " << e.what()
                << "\n";
    }
  }
  progress.update(static_cast<int>(frames.size()), "done");
  progress.finish();

  if (!o.reference.empty() && scores.empty() && failed.size() < frames.size()) {
    throw std::runtime_error("no frame has a reference PNG in " + o.reference);
  }
  if (!scores.empty()) {
    rows.push_back(
        {"mean (" + std::to_string(scores.size()) + " frames)", lsf::averageMetrics(scores)});
    std::cout << "Scores of " << lsf::methodName(params.method) << " against "
              << (o.holdout == "even" ? "the odd rings (hold-out)" : o.reference) << ":\n\n"
              << lsf::formatDepthTable(rows) << "\n";
  }
  if (!stats.empty()) std::cout << "Time per stage:\n\n" << lsf::formatTimingSummary(stats);
  std::cout << "Wrote " << stats.size() << " depth PNGs" << (o.save_pcd ? " and PCD files" : "")
            << " to " << o.out << "\n";
  if (!failed.empty() || !incomplete.empty()) {
    std::string names;
    for (const auto& name : failed) names += " " + name;
    std::cerr << "kitti_runner: " << failed.size() << " of " << frames.size() << " frames failed"
              << (failed.empty() ? "" : ":" + names) << "; " << incomplete.size()
              << " incomplete frames skipped\n";
  }
  return failed.empty() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  try {
    options = parseOptions(argc, argv);
  } catch (const lsf::UsageError& e) {
    std::cerr << "kitti_runner: " << e.what() << "\n\n" << kUsage;
    return 2;
  }
  if (options.drive.empty()) {  // --help
    std::cout << kUsage;
    return 0;
  }
  try {
    return run(options);
  } catch (const std::exception& e) {
    std::cerr << "\nkitti_runner: error: " << e.what() << "\n";
    return 1;
  }
}
