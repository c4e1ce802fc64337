// fusion_benchmark: wall time of every stage of the fusion on one frame (KITTI raw or the
// synthetic street at any size and ring count), beside OpenCV's StereoSGBM on the same pair in
// the same run: median over N repetitions after a warm-up, fused and SGBM alternating so that both
// see the same machine. Then the LiDAR stages alone (ring recovery, projection, BI*, BF*) on the
// left view, which the pipeline's rows sum over both views.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/core/patchmatch/simd.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/core/upsampling.h"
#include "lidar_stereo_fusion/eval/report.h"
#include "lidar_stereo_fusion/eval/stereo_check.h"
#include "lidar_stereo_fusion/io/cli.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/params_yaml.h"
#include "lidar_stereo_fusion/io/process_memory.h"
#include "lidar_stereo_fusion/io/simd_env.h"
#include "lidar_stereo_fusion/sim/synthetic_frame.h"

namespace lsf = lidar_stereo_fusion;

namespace {

const char* const kDrive = "kitti_raw/2011_09_26/2011_09_26_drive_0009_sync";

const char* const kUsage = R"(Usage: fusion_benchmark [options]

Times every stage of the fusion on one frame and OpenCV's StereoSGBM (MODE_SGBM_3WAY, 128
disparities, block 5, the same thread count) on the same pair, alternating, after one warm-up
run of each; prints the median [ms] per stage, SGBM's median and the ratio fused / SGBM (median
of the per-repetition ratios); then the LiDAR stages alone on the left view (ring recovery by
sweep order and, on the sweep shuffled, by the beam model; projection, BI* and BF* up-sampling),
median [ms] each.

Options:
  --kitti-raw <dir>  the KITTI drive (default: the shared data's drive 0009, found from the
                     build's data folder or env LSF_DATA_DIR)
  --frame <name>     frame name, e.g. 0000000000 (default: the first); `all`: every frame, one
                     line each
  --synthetic WxH    the synthetic street at this size instead of KITTI (e.g. 1280x720)
  --rings 64|128     LiDAR rings of the synthetic street (default 64)
  --repeat N         timed repetitions (default 5)
  --method <name>    fused_bi (default) | fused_bf | pms | lidar_bi | lidar_bf
  --threads N        threads for both (default 0 = all cores)
  --params <yaml>    parameters (e.g. config/paper.yaml); --method overrides its 'method'
  --no-sgbm          skip the SGBM reference
  --release-memory   freed memory goes back to the kernel as glibc decides (the default keeps it,
                     as the node's keep_freed_memory does: io/process_memory.h)
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
  std::string drive, frame, method, params, synthetic;
  int repeat = 5, threads = 0, rings = 64;
  bool sgbm = true, keep_memory = true;
};

std::string defaultDrive() {
  const char* env = std::getenv("LSF_DATA_DIR");
  const std::string data = env && *env ? env : LSF_DEFAULT_DATA_DIR;
  return data + "/" + kDrive;
}

Options parseOptions(int argc, char** argv) {
  const lsf::CommandLine cl(argc, argv,
                            {"--kitti-raw", "--frame", "--repeat", "--method", "--threads",
                             "--params", "--synthetic", "--rings"},
                            {"--no-sgbm", "--release-memory"});
  Options o;
  o.sgbm = !cl.has("--no-sgbm");
  o.keep_memory = !cl.has("--release-memory");
  o.drive = cl.value("--kitti-raw", defaultDrive());
  o.frame = cl.value("--frame");
  o.synthetic = cl.value("--synthetic");
  o.rings = std::stoi(cl.choice("--rings", "64", {"64", "128"}));
  o.repeat = cl.intValue("--repeat", 5, 1, 10000);
  o.threads = cl.intValue("--threads", 0, 0, lsf::PatchMatchParams::kMaxThreads);
  if (cl.has("--method")) {
    o.method = cl.choice("--method", "", {"fused_bi", "fused_bf", "pms", "lidar_bi", "lidar_bf"});
  }
  o.params = cl.value("--params");
  return o;
}

/// One input to time, with a name for the report.
struct Case {
  std::string name;
  lsf::FusionInput input;
};

std::vector<Case> kittiCases(const Options& o) {
  if (!std::filesystem::is_directory(o.drive)) {
    throw std::runtime_error("KITTI drive not found: " + o.drive +
                             " (pass --kitti-raw <drive_sync_dir> or set LSF_DATA_DIR)");
  }
  const auto calib = lsf::kitti::readCalibration(lsf::kitti::calibrationDirOf(o.drive));
  const auto frames = lsf::kitti::listFrames(o.drive);
  if (frames.empty()) throw std::runtime_error("no complete frame in " + o.drive);
  std::vector<Case> cases;
  for (const auto& f : frames) {
    const bool wanted =
        o.frame == "all" || f.name == o.frame || (o.frame.empty() && &f == &frames.front());
    if (!wanted) continue;
    const lsf::kitti::FrameData data = lsf::kitti::loadFrame(f, calib.camera);
    cases.push_back({f.name, {data.left, data.right, data.cloud, calib.T_cam_velo, calib.camera}});
  }
  if (cases.empty()) throw std::runtime_error("frame " + o.frame + " not found in " + o.drive);
  return cases;
}

Case syntheticCase(const Options& o) {
  int w = 0, h = 0;
  if (std::sscanf(o.synthetic.c_str(), "%dx%d", &w, &h) != 2 || w < 64 || h < 32 || w > 8192 ||
      h > 8192) {
    throw lsf::UsageError("--synthetic wants WxH with 64 <= W <= 8192, 32 <= H <= 8192, got '" +
                          o.synthetic + "'");
  }
  lsf::sim::SyntheticParams params = lsf::sim::SyntheticParams().resized(w, h);
  params.rings = o.rings;
  const lsf::sim::SyntheticFrame f = lsf::sim::generateStreetFrame(params);
  return {"synthetic " + o.synthetic + ", " + std::to_string(o.rings) + " rings",
          {f.left, f.right, f.cloud, f.T_cam_lidar, f.camera}};
}

/// Medians of one case: pipeline stages and SGBM.
struct Timing {
  std::vector<lsf::FrameStats> stats;
  std::vector<double> sgbm_ms, ratios;
};

Timing timeCase(const Case& c, lsf::FusionPipeline& pipeline, cv::StereoSGBM* sgbm, int repeat) {
  Timing t;
  cv::Mat sgbm_disparity;
  pipeline.process(c.input);  // warm-up: allocations, caches
  if (sgbm) sgbm->compute(c.input.left, c.input.right, sgbm_disparity);
  for (int i = 0; i < repeat; ++i) {
    t.stats.push_back(pipeline.process(c.input).stats);
    if (!sgbm) continue;
    t.sgbm_ms.push_back(
        timeMs([&] { sgbm->compute(c.input.left, c.input.right, sgbm_disparity); }));
    t.ratios.push_back(t.stats.back().total_ms / t.sgbm_ms.back());
  }
  return t;
}

double medianOf(const std::vector<lsf::FrameStats>& stats, double lsf::FrameStats::*field) {
  std::vector<double> v;
  for (const auto& s : stats) v.push_back(s.*field);
  return lsf::median(v);
}

void printRow(const char* name, double ms) { std::printf("| %-38s | %9.2f |\n", name, ms); }

void printStages(const Timing& t) {
  std::printf("\n| %-38s | %9s |\n|---|---|\n", "stage (median)", "ms");
  printRow("projection (both views)", medianOf(t.stats, &lsf::FrameStats::projection_ms));
  printRow("up-sampling + confidence (both views)",
           medianOf(t.stats, &lsf::FrameStats::upsampling_ms));
  printRow("PatchMatch", medianOf(t.stats, &lsf::FrameStats::patchmatch_ms));
  for (size_t i = 0; i < t.stats.front().patchmatch_steps.size(); ++i) {  // the same every run
    std::vector<double> ms;
    for (const auto& s : t.stats) ms.push_back(s.patchmatch_steps[i].ms);
    printRow(("  " + t.stats.front().patchmatch_steps[i].name).c_str(), lsf::median(ms));
  }
  printRow("depth", medianOf(t.stats, &lsf::FrameStats::depth_ms));
  printRow("total per frame (pipeline)", medianOf(t.stats, &lsf::FrameStats::total_ms));
  if (!t.sgbm_ms.empty()) {
    printRow("OpenCV StereoSGBM (same pair, threads)", lsf::median(t.sgbm_ms));
    std::printf("\nfused / SGBM = %.2f (median of %zu paired runs)\n", lsf::median(t.ratios),
                t.ratios.size());
  }
  const double total = medianOf(t.stats, &lsf::FrameStats::total_ms);
  std::printf("%.2f frames/s (pipeline median %.1f ms)\n", 1000.0 / total, total);
}

/// The LiDAR stages alone on the left view, median wall time [ms] of `repeat` runs each (was the
/// data test TimingOfProjectionAndUpsampling; the aim: projection + BI* < 30 ms, BF* well under
/// 100 ms on KITTI).
void printLidarStages(const Case& c, const lsf::FusionParams& params, int repeat) {
  std::vector<double> rings, beams, projection, bi, bf;
  lsf::LidarCloud shuffled = c.input.cloud;  // a sweep whose order says nothing (issue 31)
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(1));
  for (int i = 0; i < repeat; ++i) {
    lsf::LidarCloud any_order = shuffled;
    beams.push_back(timeMs([&] { lsf::recoverRingsByBeamModel(any_order, 128); }));
    lsf::LidarCloud cloud = c.input.cloud;
    rings.push_back(timeMs([&] { lsf::recoverRingsBySweepOrder(cloud); }));
    lsf::SparseDisparity sparse;
    projection.push_back(timeMs([&] {
      sparse = lsf::projectCloud(cloud, c.input.T_cam_lidar, c.input.camera, params.projection);
    }));
    bi.push_back(timeMs([&] { lsf::upsampleBI(sparse, c.input.left, params.bi); }));
    bf.push_back(timeMs([&] { lsf::upsampleBF(sparse, params.bf); }));
  }
  std::vector<double> projection_bi;
  for (int i = 0; i < repeat; ++i) projection_bi.push_back(projection[i] + bi[i]);
  std::printf("\n| %-38s | %9s |\n|---|---|\n", "LiDAR stage alone, left view (median)", "ms");
  printRow("ring recovery by sweep order", lsf::median(rings));
  printRow("ring recovery by beam model (shuffled)", lsf::median(beams));
  printRow("projection", lsf::median(projection));
  printRow("BI* up-sampling", lsf::median(bi));
  printRow("projection + BI*", lsf::median(projection_bi));
  printRow("BF* up-sampling", lsf::median(bf));
}

int run(const Options& o) {
  lsf::FusionParams params;
  if (!o.params.empty()) lsf::loadParamsYaml(o.params, params);
  if (!o.method.empty()) params.method = lsf::parseMethod(o.method);
  params.patchmatch.num_threads = o.threads;
  lsf::applySimdEnvironment(params);
  std::string memory_problem;
  const bool kept = o.keep_memory && lsf::keepFreedMemory(&memory_problem);
  if (!memory_problem.empty())
    std::fprintf(stderr, "fusion_benchmark: %s\n", memory_problem.c_str());
  const int threads = o.threads > 0 ? o.threads : omp_get_max_threads();
  omp_set_num_threads(threads);
  cv::setNumThreads(threads);
  params.validate();

  const std::vector<Case> cases =
      o.synthetic.empty() ? kittiCases(o) : std::vector<Case>{syntheticCase(o)};
  const cv::Size size = cases.front().input.left.size();
  std::printf(
      "fusion_benchmark: %s (%dx%d, %zu points), method %s, %d threads, SIMD %s, freed memory "
      "%s, 1 warm-up + %d runs\n",
      cases.size() == 1 ? cases.front().name.c_str() : "every frame", size.width, size.height,
      cases.front().input.cloud.size(), lsf::methodName(params.method).c_str(), threads,
      lsf::simdPathName(params.patchmatch.simd_path), kept ? "kept" : "released", o.repeat);
  cv::Ptr<cv::StereoSGBM> sgbm;
  if (o.sgbm) {
    sgbm = lsf::referenceSgbm();
  }
  lsf::FusionPipeline pipeline(params);
  if (cases.size() == 1) {
    printStages(timeCase(cases.front(), pipeline, sgbm.get(), o.repeat));
    printLidarStages(cases.front(), params, o.repeat);
    return 0;
  }
  std::printf(
      "\n| frame | fused ms | PatchMatch ms | SGBM ms | fused / SGBM |\n|---|---|---|---|---|\n");
  std::vector<double> ratios;
  for (const Case& c : cases) {
    const Timing t = timeCase(c, pipeline, sgbm.get(), o.repeat);
    const double r = t.ratios.empty() ? 0.0 : lsf::median(t.ratios);
    ratios.push_back(r);
    std::printf("| %s | %.1f | %.1f | %.1f | %.2f |\n", c.name.c_str(),
                medianOf(t.stats, &lsf::FrameStats::total_ms),
                medianOf(t.stats, &lsf::FrameStats::patchmatch_ms),
                t.sgbm_ms.empty() ? 0.0 : lsf::median(t.sgbm_ms), r);
  }
  std::printf("\nmedian fused / SGBM over %zu frames: %.2f\n", cases.size(), lsf::median(ratios));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return lsf::toolMain("fusion_benchmark", kUsage, argc, argv,
                       [&] { return run(parseOptions(argc, argv)); });
}
