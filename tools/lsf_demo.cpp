// lsf_demo: the README demo. Runs the whole method on a synthetic street with exact ground truth
// (default) or on the KITTI sample (--kitti, scored on held-out LiDAR rings), prints a table of
// metrics per method and writes pictures a person can look at. Also generates the synthetic scene
// in the KITTI raw layout (--generate) for the offline runner.
//
//   lsf_demo [--out DIR] [--seed N] [--fast] [--rings 64|128] [--methods a,b,...]
//   lsf_demo --kitti [DRIVE_DIR] [--frame NAME] [--out DIR] [--fast] [--methods a,b,...]
//   lsf_demo --generate DIR [--seed N] [--frames N] [--rings 64|128] [--fast]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "lidar_stereo_fusion/core/metrics.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/io/cli.h"
#include "lidar_stereo_fusion/io/simd_env.h"
#include "lidar_stereo_fusion/sim/kitti_export.h"
#include "lidar_stereo_fusion/sim/synthetic_frame.h"
#include "lsf_demo/demo_case.h"  // the cases and the pictures

namespace lsf = lidar_stereo_fusion;
namespace fs = std::filesystem;

namespace {

using lsf_demo::DemoCase;
using lsf_demo::kFastHeight;
using lsf_demo::kFastWidth;
using lsf_demo::MethodRun;
using lsf_demo::secondsSince;

const char* const kUsage = R"(Usage:
  lsf_demo [--out DIR] [--seed N] [--fast] [--rings 64|128] [--methods a,b,...]
      synthetic street with exact ground truth (default)
  lsf_demo --kitti [DRIVE_DIR] [--frame NAME] [--out DIR] [--fast] [--methods ...]
      the KITTI sample, scored on held-out LiDAR rings (even rings in, odd rings out)
  lsf_demo --generate DIR [--seed N] [--frames N] [--rings 64|128] [--fast]
      writes the synthetic street in the KITTI raw layout (+ exact depth PNGs)
Options:
  --out DIR      pictures go here (default ./demo_output)
  --seed N       scene seed (default 1)
  --fast         half-size images (620x188) for a quick look
  --methods L    comma-separated subset of fused_bi,fused_bf,lidar_bi,lidar_bf,pms
  --help         this text
)";

struct Options {
  enum class Mode { kSynthetic, kKitti, kGenerate } mode = Mode::kSynthetic;
  std::string out = "demo_output";
  std::string kitti_dir;  ///< empty: search the default sample
  std::string frame;      ///< KITTI frame name, empty: the first
  std::string generate_dir;
  uint64_t seed = 1;
  int frames = 3;
  int rings = 64;
  bool fast = false;
  std::vector<lsf::Method> methods = {lsf::Method::kFusedBI, lsf::Method::kFusedBF,
                                      lsf::Method::kLidarBI, lsf::Method::kLidarBF,
                                      lsf::Method::kPlainPMS};
};

std::vector<lsf::Method> parseMethods(const std::string& list) {
  std::vector<lsf::Method> methods;
  std::stringstream in(list);
  std::string name;
  while (std::getline(in, name, ',')) {
    if (name.empty()) continue;
    try {
      methods.push_back(lsf::parseMethod(name));
    } catch (const std::invalid_argument& e) {
      throw lsf::UsageError(std::string("--methods: ") + e.what());
    }
  }
  if (methods.empty()) throw lsf::UsageError("--methods needs at least one method");
  return methods;
}

long parseInteger(const std::string& text, const std::string& flag, long lo, long hi) {
  size_t used = 0;
  long value = 0;
  try {
    value = std::stol(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || value < lo || value > hi) {
    throw lsf::UsageError(flag + " needs an integer in [" + std::to_string(lo) + ", " +
                          std::to_string(hi) + "], got '" + text + "'");
  }
  return value;
}

Options parseOptions(int argc, char** argv) {
  Options o;
  const std::vector<std::string> args(argv + 1, argv + argc);
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const bool has_next = i + 1 < args.size();
    const bool next_is_value = has_next && args[i + 1].rfind("--", 0) != 0;
    auto value = [&]() -> const std::string& {
      if (!next_is_value) throw lsf::UsageError(a + " needs a value");
      return args[++i];
    };
    if (a == "--kitti") {
      o.mode = Options::Mode::kKitti;
      if (next_is_value) o.kitti_dir = args[++i];
    } else if (a == "--generate") {
      o.mode = Options::Mode::kGenerate;
      o.generate_dir = value();
    } else if (a == "--out") {
      o.out = value();
    } else if (a == "--seed") {
      o.seed = static_cast<uint64_t>(parseInteger(value(), a, 0, 1L << 40));
    } else if (a == "--frames") {
      o.frames = static_cast<int>(parseInteger(value(), a, 1, 10000));
    } else if (a == "--rings") {
      o.rings = static_cast<int>(parseInteger(value(), a, 64, 128));
    } else if (a == "--frame") {
      o.frame = value();
    } else if (a == "--methods") {
      o.methods = parseMethods(value());
    } else if (a == "--fast") {
      o.fast = true;
    } else {
      throw lsf::UsageError("unknown argument '" + a + "'");
    }
  }
  if (o.rings != 64 && o.rings != 128) throw lsf::UsageError("--rings must be 64 or 128");
  return o;
}

// ------------------------------------------------------------------------------------------------
// The methods on one case, and the table of their scores
// ------------------------------------------------------------------------------------------------

/// The pipeline parameters of the demo: the defaults, with the image-wide disparity range scaled
/// with the image width (the default 192 px is for KITTI's 1242 px).
lsf::FusionParams demoParams(lsf::Method method, int width) {
  lsf::FusionParams params;
  params.method = method;
  params.patchmatch.max_disparity = std::max(32.0, std::round(192.0 * width / 1242.0));
  lsf::applySimdEnvironment(params);
  return params;
}

cv::Mat1f maskedDepth(const cv::Mat1f& depth, const cv::Mat1b& mask) {
  cv::Mat1f out = cv::Mat1f::zeros(depth.size());
  depth.copyTo(out, mask);
  return out;
}

std::vector<MethodRun> runMethods(const DemoCase& c, const std::vector<lsf::Method>& methods) {
  std::vector<MethodRun> runs;
  for (lsf::Method m : methods) {
    std::cout << "  running " << lsf::methodName(m) << " ..." << std::flush;
    lsf::FusionPipeline pipeline(demoParams(m, c.input.camera.width));
    MethodRun run{m, pipeline.process(c.input), {}, {}};
    run.all = lsf::evaluateDepth(run.result.depth, c.reference_depth, c.input.camera);
    for (const auto& region : c.regions) {
      run.regions.push_back(lsf::evaluateDepth(
          run.result.depth, maskedDepth(c.reference_depth, region.mask), c.input.camera));
    }
    std::printf(" %.1f s\n", run.result.stats.total_ms / 1000.0);
    runs.push_back(std::move(run));
  }
  return runs;
}

void printTable(const DemoCase& c, const std::vector<MethodRun>& runs) {
  std::printf("\n%s\n", c.title.c_str());
  std::printf("%-9s %8s %9s %8s %8s %7s %7s %7s %7s", "method", "MAE[mm]", "RMSE[mm]", "iMAE",
              "iRMSE", ">2px", ">3px", ">5px", "cover");
  for (const auto& region : c.regions) {
    std::printf(" %*s", std::max(9, static_cast<int>(region.column.size())), region.column.c_str());
  }
  std::printf(" %8s\n", "time[s]");
  for (const MethodRun& r : runs) {
    const lsf::DepthMetrics& m = r.all;
    std::printf("%-9s %8.0f %9.0f %8.2f %8.2f %6.2f%% %6.2f%% %6.2f%% %6.1f%%",
                lsf::methodName(r.method).c_str(), m.mae_mm, m.rmse_mm, m.imae_per_km,
                m.irmse_per_km, 100 * m.bad2, 100 * m.bad3, 100 * m.bad5, 100 * m.coverage);
    for (size_t i = 0; i < c.regions.size(); ++i) {
      std::printf(" %*.0f", std::max(9, static_cast<int>(c.regions[i].column.size())),
                  r.regions[i].mae_mm);
    }
    std::printf(" %8.2f\n", r.result.stats.total_ms / 1000.0);
  }
  std::printf("Scored on %d reference pixels (%s).\n", runs.empty() ? 0 : runs.front().all.count,
              c.dense_reference ? "dense exact ground truth, sky excluded"
                                : "held-out LiDAR rings: a consistency check, not ground truth");
  std::printf(
      "iMAE/iRMSE in 1/km; >Npx: disparity error > N px; pixels without an estimate count "
      "as errors (KITTI devkit).\n");
  for (const auto& region : c.regions) {
    std::printf("%s: MAE [mm] over the %d pixels of %s.\n", region.column.c_str(),
                cv::countNonZero(region.mask & (c.reference_depth > 0.f)),
                region.description.c_str());
  }
}

// ------------------------------------------------------------------------------------------------
// The synthetic street's parameters, --generate, the demo
// ------------------------------------------------------------------------------------------------

lsf::sim::SyntheticParams syntheticParams(const Options& o) {
  lsf::sim::SyntheticParams p;
  p.seed = o.seed;
  p.rings = o.rings;
  return o.fast ? p.resized(kFastWidth, kFastHeight) : p;
}

int generate(const Options& o) {
  const lsf::sim::SyntheticParams p = syntheticParams(o);
  lsf::sim::KittiExportOptions e;
  e.num_frames = o.frames;
  const auto start = std::chrono::steady_clock::now();
  const std::string drive = lsf::sim::writeKittiDrive(o.generate_dir, p, e);
  std::printf(
      "Wrote %d synthetic frames (seed %llu, %dx%d, %d rings) in %.1f s to\n  %s\n"
      "Exact depth: %s/proj_depth/groundtruth/image_02/*.png (KITTI format, m * 256)\n",
      o.frames, static_cast<unsigned long long>(p.seed), p.width, p.height, p.rings,
      secondsSince(start), fs::absolute(drive).c_str(), drive.c_str());
  return 0;
}

int runDemo(const Options& o) {
  lsf::sim::SyntheticFrame frame;
  const bool synthetic = o.mode == Options::Mode::kSynthetic;
  const DemoCase c = synthetic ? lsf_demo::syntheticCase(syntheticParams(o), &frame)
                               : lsf_demo::kittiCase(o.kitti_dir, o.frame, o.fast);
  if (synthetic) lsf_demo::printOcclusionScore(frame);
  const std::vector<MethodRun> runs = runMethods(c, o.methods);
  printTable(c, runs);
  const fs::path composite = lsf_demo::writePictures(c, runs, o.out);
  std::printf("\nPictures written to %s\n  (overview: %s)\n",
              fs::absolute(o.out).lexically_normal().c_str(),
              fs::absolute(composite).lexically_normal().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return lsf::toolMain("lsf_demo", kUsage, argc, argv, [&] {
    const Options o = parseOptions(argc, argv);
    return o.mode == Options::Mode::kGenerate ? generate(o) : runDemo(o);
  });
}
