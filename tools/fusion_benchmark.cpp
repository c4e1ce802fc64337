// fusion_benchmark: wall time of every stage of the fusion on one KITTI frame (1242x375), median
// over N repetitions after a warm-up run.
#include <omp.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "lidar_stereo_fusion/core/patchmatch/simd.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/io/cli.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/params_yaml.h"
#include "lidar_stereo_fusion/io/report.h"

namespace lsf = lidar_stereo_fusion;

namespace {

const char* const kDefaultDrive = "../shared/data/kitti_raw/2011_09_26/2011_09_26_drive_0009_sync";

const char* const kUsage = R"(Usage: fusion_benchmark [options]

Times every stage of the fusion on one KITTI raw frame: one warm-up run, then --repeat runs;
prints the median [ms] per stage and per frame.

Options:
  --kitti-raw <dir>  the drive (default ../shared/data/kitti_raw/2011_09_26/
                     2011_09_26_drive_0009_sync, relative to the working folder)
  --frame <name>     frame name, e.g. 0000000000 (default: the first frame)
  --repeat N         timed repetitions (default 5)
  --method <name>    fused_bi (default) | fused_bf | pms | lidar_bi | lidar_bf
  --threads N        OpenMP threads (default 0 = all cores)
  --params <yaml>    parameters; --method overrides its 'method'
  --help             this text
)";

using Clock = std::chrono::steady_clock;

/// Wall time of `f` [ms].
double timeMs(const std::function<void()>& f) {
  const auto start = Clock::now();
  f();
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct Options {
  std::string drive = kDefaultDrive, frame, method, params;
  int repeat = 5, threads = 0;
  bool help = false;
};

Options parseOptions(int argc, char** argv) {
  const lsf::CommandLine cl(
      argc, argv, {"--kitti-raw", "--frame", "--repeat", "--method", "--threads", "--params"},
      {"--help"});
  Options o;
  o.help = cl.has("--help");
  o.drive = cl.value("--kitti-raw", kDefaultDrive);
  o.frame = cl.value("--frame");
  o.repeat = cl.intValue("--repeat", 5, 1, 10000);
  o.threads = cl.intValue("--threads", 0, 0, 1024);
  if (cl.has("--method")) {
    o.method = cl.choice("--method", "", {"fused_bi", "fused_bf", "pms", "lidar_bi", "lidar_bf"});
  }
  o.params = cl.value("--params");
  return o;
}

lsf::kitti::Frame findFrame(const Options& o) {
  if (!std::filesystem::is_directory(o.drive)) {
    throw std::runtime_error("KITTI drive not found: " + o.drive +
                             " (run from the package root next to ../shared/data, or pass "
                             "--kitti-raw <drive_sync_dir>)");
  }
  const auto frames = lsf::kitti::listFrames(o.drive);
  if (frames.empty()) throw std::runtime_error("no complete frame in " + o.drive);
  if (o.frame.empty()) return frames.front();
  for (const auto& f : frames) {
    if (f.name == o.frame) return f;
  }
  throw std::runtime_error("frame " + o.frame + " not found in " + o.drive);
}

/// Median times [ms] of the stages inside up-sampling, measured directly on the core functions.
struct UpsamplingDetail {
  std::vector<double> rings, completion, removal, interpolation, bounds, bf;
};

void timeUpsamplingDetail(const lsf::FusionInput& input, lsf::LidarCloud cloud,
                          const lsf::FusionParams& params, UpsamplingDetail& detail) {
  detail.rings.push_back(timeMs([&] { lsf::recoverRingsBySweepOrder(cloud); }));
  const lsf::SparseDisparity sparse =
      lsf::projectCloud(cloud, input.T_cam_lidar, input.camera, params.projection);
  lsf::ScanLines lines;
  detail.completion.push_back(timeMs([&] { lines = lsf::completeScanLines(sparse, params.bi); }));
  detail.removal.push_back(
      timeMs([&] { lsf::removeOccludedPoints(lines, input.left, params.bi); }));
  detail.interpolation.push_back(
      timeMs([&] { lsf::interpolateBetweenScanLines(lines, params.bi); }));
  detail.bounds.push_back(
      timeMs([&] { lsf::computeScanLineBounds(lines, params.patchmatch.bound_margin); }));
  detail.bf.push_back(timeMs([&] { lsf::upsampleBF(sparse, params.bf); }));
}

void printRow(const char* name, double ms) { std::printf("| %-38s | %9.2f |\n", name, ms); }

int run(const Options& o) {
  lsf::FusionParams params;
  if (!o.params.empty()) lsf::loadParamsYaml(o.params, params);
  if (!o.method.empty()) params.method = lsf::parseMethod(o.method);
  params.patchmatch.num_threads = o.threads;
  if (o.threads > 0) omp_set_num_threads(o.threads);
  params.validate();

  const lsf::kitti::Frame frame = findFrame(o);
  const auto calib = lsf::kitti::readCalibration(lsf::kitti::calibrationDirOf(o.drive));
  lsf::kitti::FrameData data;
  const double load_ms = timeMs([&] { data = lsf::kitti::loadFrame(frame, calib.camera); });
  const lsf::FusionInput input{data.left, data.right, data.cloud, calib.T_cam_velo, calib.camera};
  lsf::LidarCloud raw_cloud = data.cloud;
  for (auto& p : raw_cloud) p.ring = -1;

  std::printf(
      "fusion_benchmark: frame %s (%dx%d, %zu points), method %s, %d threads, SIMD %s, "
      "1 warm-up + %d runs\n",
      frame.name.c_str(), calib.camera.width, calib.camera.height, data.cloud.size(),
      lsf::methodName(params.method).c_str(), o.threads > 0 ? o.threads : omp_get_max_threads(),
      lsf::simdLevel(), o.repeat);
  lsf::FusionPipeline pipeline(params);
  pipeline.process(input);  // warm-up: allocations, caches
  std::vector<lsf::FrameStats> stats;
  UpsamplingDetail detail;
  lsf::ProgressBar progress(std::cerr, o.repeat, false);
  for (int i = 0; i < o.repeat; ++i) {
    stats.push_back(pipeline.process(input).stats);
    timeUpsamplingDetail(input, raw_cloud, params, detail);
    if (o.repeat >= 3) progress.update(i + 1, "runs");
  }

  auto medianOf = [&](double lsf::FrameStats::*field) {
    std::vector<double> v;
    for (const auto& s : stats) v.push_back(s.*field);
    return lsf::median(v);
  };
  std::printf("\n| %-38s | %9s |\n|---|---|\n", "stage (median)", "ms");
  printRow("load frame (PNG + .bin + rings, once)", load_ms);
  printRow("projection", medianOf(&lsf::FrameStats::projection_ms));
  printRow("up-sampling", medianOf(&lsf::FrameStats::upsampling_ms));
  printRow("PatchMatch", medianOf(&lsf::FrameStats::patchmatch_ms));
  printRow("depth", medianOf(&lsf::FrameStats::depth_ms));
  printRow("total per frame (pipeline)", medianOf(&lsf::FrameStats::total_ms));
  std::printf(
      "\nInside the stages (core functions timed alone, one view):\n\n"
      "| %-38s | %9s |\n|---|---|\n",
      "function (median)", "ms");
  printRow("ring recovery (sweep order)", lsf::median(detail.rings));
  printRow("BI* scan-line completion", lsf::median(detail.completion));
  printRow("BI* Algorithm 1 (occlusion removal)", lsf::median(detail.removal));
  printRow("BI* interpolation (Eq. 3)", lsf::median(detail.interpolation));
  printRow("scan-line search bounds", lsf::median(detail.bounds));
  printRow("BF* bilateral up-sampling", lsf::median(detail.bf));
  const double total = medianOf(&lsf::FrameStats::total_ms);
  std::printf("\n%.2f frames/s (pipeline median %.1f ms)\n", 1000.0 / total, total);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  try {
    options = parseOptions(argc, argv);
  } catch (const lsf::UsageError& e) {
    std::cerr << "fusion_benchmark: " << e.what() << "\n\n" << kUsage;
    return 2;
  }
  if (options.help) {
    std::cout << kUsage;
    return 0;
  }
  try {
    return run(options);
  } catch (const std::exception& e) {
    std::cerr << "fusion_benchmark: error: " << e.what() << "\n";
    return 1;
  }
}
