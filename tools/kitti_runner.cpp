// kitti_runner: runs the fusion on every frame of a KITTI raw drive and writes KITTI
// depth-completion PNGs; optionally scores them against reference depth PNGs or a ring hold-out.
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "kitti_runner/output_folder.h"  // the output folder and --save-vis
#include "lidar_stereo_fusion/core/depth.h"
#include "lidar_stereo_fusion/core/metrics.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/eval/holdout.h"
#include "lidar_stereo_fusion/eval/photometric_check.h"
#include "lidar_stereo_fusion/eval/report.h"
#include "lidar_stereo_fusion/io/cli.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/kitti_sweep.h"
#include "lidar_stereo_fusion/io/params_yaml.h"
#include "lidar_stereo_fusion/io/pcd.h"
#include "lidar_stereo_fusion/io/process_memory.h"
#include "lidar_stereo_fusion/io/progress.h"
#include "lidar_stereo_fusion/io/simd_env.h"

namespace lsf = lidar_stereo_fusion;
namespace fs = std::filesystem;

namespace {

using kitti_runner::createDirectory;
using kitti_runner::requireApart;
using kitti_runner::requireWritable;
using kitti_runner::saveVisualisation;

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
  --deskew             untwist each sweep to its image_02 instant (point times from the azimuth
                       and velodyne_points/timestamps_{start,end}.txt, constant velocity from
                       oxts/data/<frame>.txt and calib_imu_to_velo.txt); a frame without its
                       packet or stamps is named and processed as measured (doc/motion_kitti.md)
  --photometric-check  per frame, the best shift delta in [-3, 3] px of image_03 at (u - d + delta,
                       v) for image_02 at each LiDAR pixel (u, v, d): median delta, median |delta|,
                       share of |delta| <= 0.5 px; with --deskew before and after
  --save-pcd           also write <out>/<frame>.pcd: the coloured points of the depth (those of
                       the node's points2: every pixel with depth, back-projected into the left
                       optical frame [m], in row-major order), with PCL's writer: fields x y z
                       rgb, DATA binary_compressed (pcl_viewer, CloudCompare, PCL's converters)
  --frames N           process only the first N frames
  --help               this text

Frames with image_02 but without image_03 or the .bin are named and skipped; a frame that fails
(corrupt .bin or image, ...) is named and the run goes on with the next one.

Exit status: 0 on success, 1 when any frame failed (or, with --deskew, was not deskewed) or on missing or corrupt input (calibration,
drive, parameters, unwritable output folder), 2 on a bad command line.
)";

struct Options {
  std::string drive, out, params, reference, holdout = "none";
  std::optional<std::string> method;
  bool save_vis = false, deskew = false, photometric_check = false, save_pcd = false;
  int frames = 0;  // 0 = all
};

/// What --deskew needs for every frame (read once).
struct Deskew {
  lsf::kitti::DriveStamps stamps;
  Eigen::Isometry3d T_velo_imu = Eigen::Isometry3d::Identity();
};

/// What the frames give.
struct Results {
  std::vector<lsf::DepthRow> rows;
  std::vector<lsf::DepthMetrics> scores;
  std::vector<lsf::FrameStats> stats;
  std::vector<double> deskew_ms;          ///< [ms] per deskewed frame
  std::vector<std::string> undeskewed;    ///< frames processed as measured despite --deskew
  std::vector<lsf::ShiftRow> shift_rows;  ///< --photometric-check, per frame
  std::vector<double> shifts_before, shifts_after;  ///< all frames pooled
};

Options parseOptions(int argc, char** argv) {
  const lsf::CommandLine cl(
      argc, argv,
      {"--kitti-raw", "--out", "--method", "--params", "--reference", "--frames", "--holdout"},
      {"--save-vis", "--save-pcd", "--deskew", "--photometric-check"});
  Options o;
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
  o.deskew = cl.has("--deskew");
  o.photometric_check = cl.has("--photometric-check");
  o.save_pcd = cl.has("--save-pcd");
  o.frames = cl.intValue("--frames", 0, 1, 1000000);
  return o;
}

lsf::FusionParams loadParams(const Options& o) {
  lsf::FusionParams params;
  if (!o.params.empty()) lsf::loadParamsYaml(o.params, params);
  if (o.method) params.method = lsf::parseMethod(*o.method);
  lsf::applySimdEnvironment(params);
  params.validate();
  std::string memory_problem;  // frames reuse the last frame's pages (io/process_memory.h)
  if (!lsf::keepFreedMemory(&memory_problem))
    std::cerr << "kitti_runner: " << memory_problem << "\n";
  return params;
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

/// What every frame needs.
struct Context {
  const Options& options;
  lsf::kitti::Calibration calib;
  lsf::FusionParams params;
  std::optional<Deskew> deskew;  ///< with --deskew
};

/// --photometric-check: the shifts of the sweep's LiDAR pixels in the left image.
lsf::PhotometricShifts shiftsOf(const Context& c, const lsf::kitti::FrameData& data,
                                const lsf::LidarCloud& cloud) {
  const lsf::SparseDisparity sparse =
      lsf::projectCloud(cloud, c.calib.T_cam_velo, c.calib.camera, c.params.projection);
  return lsf::photometricShifts(data.left, data.right, sparse.disparity);
}

/// --deskew: untwists the sweep and times it; a frame that cannot be deskewed (no packet or
/// stamp) is named and counted, and goes on as measured. True when deskewed.
bool deskewSweep(const Context& c, const std::string& name, lsf::LidarCloud& cloud,
                 Results& results) {
  try {
    const auto start = std::chrono::steady_clock::now();
    lsf::kitti::deskewFrame(c.options.drive, name, c.deskew->stamps, c.deskew->T_velo_imu, cloud);
    results.deskew_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
    return true;
  } catch (const std::runtime_error& e) {
    std::cerr << "\nkitti_runner: warning: frame " << name
              << " is not deskewed, processed as measured: " << e.what() << "\n";
    results.undeskewed.push_back(name);
    return false;
  }
}

/// --photometric-check before the deskew and, when the sweep was deskewed, after it; and --deskew.
void deskewAndCheck(const Context& c, const std::string& name, lsf::kitti::FrameData& data,
                    Results& results) {
  std::optional<lsf::PhotometricShifts> before;
  if (c.options.photometric_check) before = shiftsOf(c, data, data.cloud);
  const bool deskewed = c.deskew && deskewSweep(c, name, data.cloud, results);
  if (!before) return;
  lsf::ShiftRow row{name, lsf::summarizeShifts(before->shifts), std::nullopt};
  results.shifts_before.insert(results.shifts_before.end(), before->shifts.begin(),
                               before->shifts.end());
  if (deskewed) {
    const lsf::PhotometricShifts after = shiftsOf(c, data, data.cloud);
    row.after = lsf::summarizeShifts(after.shifts);
    results.shifts_after.insert(results.shifts_after.end(), after.shifts.begin(),
                                after.shifts.end());
  }
  results.shift_rows.push_back(row);
}

/// The frame's depth PNG (and PCD, pictures), its score against the reference, its stats.
void writeFrame(const Context& c, const std::string& name, const cv::Mat& left,
                const lsf::FusionResult& result, const std::optional<cv::Mat1f>& reference,
                Results& results) {
  const Options& o = c.options;
  lsf::kitti::writeDepthPng((fs::path(o.out) / (name + ".png")).string(), result.depth);
  if (o.save_pcd) {
    lsf::pcd::writeColoredPcd((fs::path(o.out) / (name + ".pcd")).string(),
                              lsf::makeColoredCloud(result.depth, left, c.calib.camera));
  }
  if (reference) {
    results.scores.push_back(lsf::evaluateDepth(result.depth, *reference, c.calib.camera));
    results.rows.push_back({name, results.scores.back()});
  }
  if (o.save_vis) {
    saveVisualisation(fs::path(o.out) / "vis", name, left, result, reference, c.calib.camera);
  }
  results.stats.push_back(result.stats);
}

/// Runs one frame and writes its outputs; throws std::runtime_error naming the problem.
void runFrame(const Context& c, const lsf::kitti::Frame& frame, lsf::FusionPipeline& pipeline,
              Results& results) {
  const Options& o = c.options;
  const lsf::kitti::Calibration& calib = c.calib;
  lsf::kitti::FrameData data = lsf::kitti::loadFrame(frame, calib.camera);
  if (!data.rings.plausible) {
    std::cerr << "\nkitti_runner: warning: frame " << frame.name << ": rings of " << frame.velodyne
              << " are implausible (" << data.rings.fallbacks << "); using "
              << lsf::ringSourceName(data.rings.source) << " (" << data.rings.rings << " rings)\n";
  }
  deskewAndCheck(c, frame.name, data, results);
  lsf::FusionInput input{data.left, data.right, {}, calib.T_cam_velo, calib.camera};
  std::optional<cv::Mat1f> reference;
  if (o.holdout == "even") {
    lsf::HoldoutCase holdout =
        lsf::makeRingHoldout(data.cloud, calib.T_cam_velo, calib.camera, c.params.projection);
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
  writeFrame(c, frame.name, data.left, result, reference, results);
}

/// The tables of --photometric-check and the time --deskew took.
void printChecks(const Options& o, const Results& results) {
  if (o.photometric_check && !results.shift_rows.empty()) {
    std::vector<lsf::ShiftRow> rows = results.shift_rows;
    lsf::ShiftRow all{"all (" + std::to_string(rows.size()) + " frames)",
                      lsf::summarizeShifts(results.shifts_before), std::nullopt};
    if (!results.shifts_after.empty()) all.after = lsf::summarizeShifts(results.shifts_after);
    rows.push_back(all);
    std::cout << "Photometric check (best shift delta of image_03 at u - d + delta, 5x5 ZNCC):\n\n"
              << lsf::formatShiftTable(rows) << "\n";
  }
  if (!results.deskew_ms.empty()) {
    double sum = 0.0;
    for (const double ms : results.deskew_ms) sum += ms;
    double total = 0.0;
    for (const lsf::FrameStats& s : results.stats) total += s.total_ms;
    std::cout << std::fixed << std::setprecision(1) << "Deskew: " << sum / results.deskew_ms.size()
              << " ms per frame (" << results.deskew_ms.size() << " frames); the pipeline: "
              << (results.stats.empty() ? 0.0 : total / results.stats.size()) << " ms per frame\n";
  }
}

/// The drive's complete frames (the first --frames), the calibration and --deskew's inputs, and
/// the output folder; warns about the incomplete frames.
std::vector<lsf::kitti::Frame> openDrive(const Options& o, std::unique_ptr<Context>& c,
                                         const lsf::FusionParams& params,
                                         std::vector<std::string>& incomplete) {
  // The drive first: a wrong --kitti-raw must be named as such, not as a missing calibration.
  std::vector<lsf::kitti::Frame> frames = lsf::kitti::listFrames(o.drive, &incomplete);
  c.reset(new Context{
      o, lsf::kitti::readCalibration(lsf::kitti::calibrationDirOf(o.drive)), params, {}});
  if (o.deskew) {  // missing drive-wide inputs fail the run; a frame's missing packet does not
    c->deskew = Deskew{lsf::kitti::readDriveStamps(o.drive),
                       lsf::kitti::readImuToVelo(lsf::kitti::calibrationDirOf(o.drive))};
  }
  for (const std::string& line : incomplete) {
    std::cerr << "kitti_runner: warning: skipped " << line << "\n";
  }
  if (frames.empty()) {
    throw std::runtime_error("no frame in " + o.drive +
                             " has image_02, image_03 and a velodyne_points .bin");
  }
  if (o.frames > 0 && static_cast<size_t>(o.frames) < frames.size()) frames.resize(o.frames);
  requireApart(o.out, o.drive, "the drive (--kitti-raw)");
  if (!o.reference.empty()) requireApart(o.out, o.reference, "the reference folder (--reference)");
  createDirectory(o.out);
  requireWritable(o.out);
  if (o.save_vis) createDirectory(fs::path(o.out) / "vis");
  return frames;
}

/// The scores, timings and checks, and what was not processed as asked.
void printResults(const Options& o, const lsf::FusionParams& params, Results& results,
                  size_t frames, const std::vector<std::string>& failed,
                  const std::vector<std::string>& incomplete) {
  const std::vector<lsf::DepthMetrics>& scores = results.scores;
  if (!scores.empty()) {
    results.rows.push_back(
        {"mean (" + std::to_string(scores.size()) + " frames)", lsf::averageMetrics(scores)});
    std::cout << "Scores of " << lsf::methodName(params.method) << " against "
              << (o.holdout == "even" ? "the odd rings (hold-out)" : o.reference) << ":\n\n"
              << lsf::formatDepthTable(results.rows) << "\n";
  }
  if (!results.stats.empty()) {
    std::cout << "Time per stage:\n\n" << lsf::formatTimingSummary(results.stats);
  }
  printChecks(o, results);
  std::cout << "Wrote " << results.stats.size() << " depth PNGs"
            << (o.save_pcd ? " and PCD files" : "") << " to " << o.out << "\n";
  if (!results.undeskewed.empty()) {
    std::string names;
    for (const auto& name : results.undeskewed) names += " " + name;
    std::cerr << "kitti_runner: " << results.undeskewed.size() << " of " << frames
              << " frames not deskewed (processed as measured):" << names << "\n";
  }
  if (!failed.empty() || !incomplete.empty()) {
    std::string names;
    for (const auto& name : failed) names += " " + name;
    std::cerr << "kitti_runner: " << failed.size() << " of " << frames << " frames failed"
              << (failed.empty() ? "" : ":" + names) << "; " << incomplete.size()
              << " incomplete frames skipped\n";
  }
}

int run(const Options& o) {
  const lsf::FusionParams params = loadParams(o);
  std::vector<std::string> incomplete;
  std::unique_ptr<Context> c;
  const std::vector<lsf::kitti::Frame> frames = openDrive(o, c, params, incomplete);
  std::cerr << "kitti_runner: " << frames.size() << " frames, method "
            << lsf::methodName(params.method)
            << (o.holdout == "even" ? ", hold-out: even rings in, odd rings scored" : "")
            << (o.deskew ? ", sweeps deskewed" : "") << "\n";
  lsf::FusionPipeline pipeline(params);
  Results results;
  std::vector<std::string> failed;
  lsf::ProgressBar progress(std::cerr, static_cast<int>(frames.size()), ::isatty(2) != 0);
  for (size_t i = 0; i < frames.size(); ++i) {
    progress.update(static_cast<int>(i), frames[i].name);
    try {
      runFrame(*c, frames[i], pipeline, results);
    } catch (const std::exception& e) {  // name it and go on with the next frame
      failed.push_back(frames[i].name);
      std::cerr << "\nkitti_runner: error: frame " << frames[i].name << " failed: " << e.what()
                << "\n";
    }
  }
  progress.update(static_cast<int>(frames.size()), "done");
  progress.finish();
  if (!o.reference.empty() && results.scores.empty() && failed.size() < frames.size()) {
    throw std::runtime_error("no frame has a reference PNG in " + o.reference);
  }
  printResults(o, params, results, frames.size(), failed, incomplete);
  return failed.empty() && results.undeskewed.empty() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  return lsf::toolMain("kitti_runner", kUsage, argc, argv,
                       [&] { return run(parseOptions(argc, argv)); });
}
