// accuracy_report: every method on every accuracy protocol (Middlebury pseudo-LiDAR layouts, KITTI
// ring hold-out, KITTI dense LiDAR against an accumulated reference, the same on the synthetic
// street against exact and LiDAR-made references), with per-region figures, as Markdown tables.
// The protocols themselves are in eval/accuracy_protocols.h, eval/accuracy_dense.h and
// eval/synthetic_dense.h; this tool parses options and prints.
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "lidar_stereo_fusion/eval/accuracy_dense.h"
#include "lidar_stereo_fusion/eval/accuracy_protocols.h"
#include "lidar_stereo_fusion/eval/accuracy_tables.h"
#include "lidar_stereo_fusion/eval/sweep_order.h"
#include "lidar_stereo_fusion/eval/synthetic_dense.h"
#include "lidar_stereo_fusion/io/cli.h"
#include "lidar_stereo_fusion/io/params_yaml.h"
#include "lidar_stereo_fusion/io/simd_env.h"

namespace lsf = lidar_stereo_fusion;

namespace {

const char* const kUsage = R"(Usage: accuracy_report [options]

Runs every method (fused = FusionParams() defaults, paper = config/paper.yaml, lidar_bi, lidar_bf,
pms, "lidar_bi else pms", nearest, ip_basic) on the accuracy protocols and prints Markdown tables:
one per layout (rows = methods, columns = metrics, mean over scenes / frames), then the
per-region tables (above the LiDAR, inside, depth edge, elsewhere inside) and, on KITTI, the
depth bands (< 10 m, 10-30 m, >= 30 m of the reference depth), and which surface the reference
has at each method's own depth edges (eval/edge_sides.h). Empty pixels are filled like the KITTI
devkit (interpolateBackground) before scoring.

  middlebury: cones + teddy: mb64 (64 ground-truth rows), mb16 (16 rows), mb42low (42 rows over
    the lower 2/3); errors in disparity px over every ground-truth pixel.
  kitti: drive 0009: ring32 (rings % 2 == 0 fed), ring16 (rings % 4 == 0 fed); the other rings'
    points are the reference depth.
  dense: drive 0009 frame 20: the full sweep fed, scored against the depth accumulated from
    sweeps 15-25 with the OXTS poses (points disagreeing with frame 20's sweep removed).
  synthetic: the synthetic street (seeds 1-3, frame 5, no data files), the full 64-ring sweep
    fed: syn_lidar scores against a reference made of LiDAR returns as KITTI's is (sweeps of
    frames 0-10, the nearest point per pixel, each return widened by its beam's footprint),
    syn_exact against the exact depth at the same pixels: the same outputs, so the two show
    what a LiDAR-made reference does to each method's score; syn_image against the exact depth
    at every pixel with a surface, above the LiDAR's view too (where the images alone decide).

Options:
  --data <dir>          the shared data folder (default: env LSF_DATA_DIR, else the build's
                        ../shared/data next to the source tree)
  --protocols <list>    comma-separated subset of middlebury,kitti,dense,synthetic (default all)
  --layouts <list>      comma-separated subset of mb64,mb16,mb42low,ring32,ring16,dense,
                        syn_exact,syn_lidar,syn_image (default all); a protocol runs only when
                        one of its layouts is chosen
  --frames N            the first N KITTI ring hold-out frames (default all 11)
  --no-kitti-pms        skip pms and "lidar_bi else pms" on KITTI, ring and dense, and on the
                        synthetic street (~15 s a frame)
  --params <yaml>       parameters of the "fused" row (and the base of lidar_*, pms), e.g. to
                        compare a tuning against the defaults; default FusionParams()
  --methods <list>      comma-separated subset of the rows: fused, paper, lidar_bi, lidar_bf, pms,
                        "lidar_bi else pms", nearest, ip_basic (default all)
  --ip-basic-blur <b>   IP-Basic's last blur: gaussian (the paper's, default), bilateral, none
  --reference <rule>    dense: how the sweeps' points of a pixel make its reference depth:
                        nearest (a z-buffer, default) or majority (the depth most sweeps agree
                        on; see doc/accuracy.md, who is right at depth edges)
  --stereo-check <px>   dense: keep only the reference pixels where OpenCV's SGBM (the
                        benchmark's) has a disparity within <px> of the reference's, as KITTI's
                        ground truth is cleaned with stereo (0 = off, default; e.g. 3)
  --keep-unverified     dense: keep other sweeps' points where frame 20's own sweep has none
                        nearby (above its top beam, its dropouts), as KITTI's ground truth does;
                        with --stereo-check 3 the reference most like KITTI's
  --sweep-order <o>     kitti and dense: the fed sweep recorded (default: rings from the sweep
                        order), or with its order lost and its rings recovered as the node does
                        for a cloud without a ring field: shuffled, image-rows, or
                        image-rows-cropped (only the points in view, as a depth-completion
                        dataset gives them); the references are unchanged
  --save-dir <dir>      write every scored case there (created if missing): each method's output
                        before the devkit fill, the reference and the left image, as
                        <layout>_<item>_<method>.tiff (32-bit float: Middlebury disparity [px],
                        else depth [m]), <layout>_<item>_reference.tiff, <layout>_<item>_left.png
  --help                this text
)";

struct Options {
  std::string data, params, ip_basic_blur = "gaussian", reference = "nearest",
                            sweep_order = "recorded", save_dir;
  double stereo_check_px = 0.0;
  std::set<std::string> methods, layouts;
  bool middlebury = true, kitti = true, dense = true, synthetic = true, kitti_pms = true;
  bool keep_unverified = false;
  int frames = 0;
};

std::set<std::string> splitList(const std::string& text) {
  std::set<std::string> items;
  std::stringstream list(text);
  std::string item;
  while (std::getline(list, item, ',')) items.insert(item);
  return items;
}

/// True when `layouts` is empty or holds one of `names`.
bool anyChosen(const std::set<std::string>& layouts, const std::vector<std::string>& names) {
  if (layouts.empty()) return true;
  for (const std::string& n : names) {
    if (layouts.count(n) > 0) return true;
  }
  return false;
}

std::string defaultDataDir() {
  if (const char* env = std::getenv("LSF_DATA_DIR"); env != nullptr && *env != '\0') return env;
  return LSF_DEFAULT_DATA_DIR;
}

Options parseOptions(int argc, char** argv) {
  const lsf::CommandLine cl(
      argc, argv,
      {"--data", "--protocols", "--layouts", "--frames", "--params", "--methods", "--ip-basic-blur",
       "--reference", "--stereo-check", "--sweep-order", "--save-dir"},
      {"--no-kitti-pms", "--keep-unverified"});
  Options o;
  o.data = cl.value("--data", defaultDataDir());
  o.frames = cl.intValue("--frames", 0, 1, 1000);
  o.kitti_pms = !cl.has("--no-kitti-pms");
  o.keep_unverified = cl.has("--keep-unverified");
  o.params = cl.value("--params", "");
  o.save_dir = cl.value("--save-dir", "");
  if (cl.has("--save-dir") && o.save_dir.empty()) throw lsf::UsageError("--save-dir: empty folder");
  o.ip_basic_blur = cl.choice("--ip-basic-blur", "gaussian", {"gaussian", "bilateral", "none"});
  o.reference = cl.choice("--reference", "nearest", {"nearest", "majority"});
  o.sweep_order = cl.choice("--sweep-order", "recorded", lsf::sweepOrderNames());
  o.stereo_check_px = cl.doubleValue("--stereo-check", 0.0, 0.0, 1000.0);
  if (cl.has("--methods")) o.methods = splitList(cl.value("--methods"));
  if (cl.has("--layouts")) o.layouts = splitList(cl.value("--layouts"));
  for (const std::string& layout : o.layouts) {
    if (!anyChosen({layout}, lsf::accuracyLayoutNames())) {
      throw lsf::UsageError("--layouts: unknown layout '" + layout +
                            "' (valid: " + lsf::joinedNames(lsf::accuracyLayoutNames()) + ")");
    }
  }
  if (cl.has("--protocols")) {
    o.middlebury = o.kitti = o.dense = o.synthetic = false;
    for (const std::string& item : splitList(cl.value("--protocols"))) {
      if (item == "middlebury") {
        o.middlebury = true;
      } else if (item == "kitti") {
        o.kitti = true;
      } else if (item == "dense") {
        o.dense = true;
      } else if (item == "synthetic") {
        o.synthetic = true;
      } else {
        throw lsf::UsageError("--protocols: unknown protocol '" + item +
                              "' (valid: middlebury, kitti, dense, synthetic)");
      }
    }
  }
  o.middlebury = o.middlebury && anyChosen(o.layouts, lsf::middleburyLayoutNames());
  o.kitti = o.kitti && anyChosen(o.layouts, lsf::kittiLayoutNames());
  o.dense = o.dense && anyChosen(o.layouts, lsf::denseLayoutNames());
  o.synthetic = o.synthetic && anyChosen(o.layouts, lsf::syntheticLayoutNames());
  if (!o.middlebury && !o.kitti && !o.dense && !o.synthetic) {
    throw lsf::UsageError(
        "--protocols and --layouts leave nothing to run (no chosen layout "
        "belongs to a chosen protocol)");
  }
  // An option that only a protocol left out would read changes nothing: say so, not ignore it.
  for (const char* option : {"--reference", "--stereo-check", "--keep-unverified"}) {
    if (cl.has(option) && !o.dense) {
      throw lsf::UsageError(std::string(option) +
                            " applies to the dense protocol, which --protocols and --layouts "
                            "leave out");
    }
  }
  if (cl.has("--sweep-order") && !o.kitti && !o.dense) {
    throw lsf::UsageError(
        "--sweep-order applies to the kitti and dense protocols, which --protocols and "
        "--layouts leave out");
  }
  if (cl.has("--frames") && !o.kitti) {
    throw lsf::UsageError(
        "--frames applies to the kitti protocol, which --protocols and --layouts leave out");
  }

  return o;
}

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

/// The protocols' options from the command line's.
lsf::AccuracyOptions accuracyOptions(const Options& o) {
  lsf::AccuracyOptions options;
  options.data_dir = o.data;
  options.kitti_frames = o.frames;
  options.kitti_pms = o.kitti_pms;
  options.sweep_order = lsf::parseSweepOrder(o.sweep_order);
  options.progress = &std::cerr;
  options.save_dir = o.save_dir;
  if (!o.save_dir.empty()) {  // before any protocol runs, not after the first case
    try {
      lsf::createSaveDir(o.save_dir);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(std::string("--save-dir: ") + e.what());
    }
  }
  options.methods = o.methods;
  options.layouts = o.layouts;
  options.ip_basic.blur = o.ip_basic_blur == "bilateral" ? lsf::IpBasicBlur::kBilateral
                          : o.ip_basic_blur == "none"    ? lsf::IpBasicBlur::kNone
                                                         : lsf::IpBasicBlur::kGaussian;
  if (!o.params.empty()) lsf::loadParamsYaml(o.params, options.fused);
  lsf::applySimdEnvironment(options.fused);
  const std::string paper = std::string(LSF_SOURCE_DIR) + "/config/paper.yaml";
  if (std::filesystem::is_regular_file(paper)) {
    lsf::FusionParams params;
    lsf::loadParamsYaml(paper, params);
    params.patchmatch.simd_path = options.fused.patchmatch.simd_path;
    options.paper = params;
  } else {
    std::cout << "> note: " << paper << " not found: the 'paper' row is skipped.\n\n";
  }
  return options;
}

/// Heads each layout's edge-sides table (eval/edge_sides.h).
const char* const kEdgeSidesTitle =
    "At each method's own depth edges (a pixel whose nearest 4-neighbour is >= 1.3x nearer), the "
    "reference has the near surface, the pixel's own far one (within 10 %), a depth between or "
    "another (summed over the items):\n\n";

void printMiddlebury(const lsf::AccuracyOptions& options) {
  const auto t = std::chrono::steady_clock::now();
  for (const auto& layout : lsf::runMiddleburyProtocol(options)) {
    std::cout << "## " << layout.name << ": " << layout.description << "\n\n"
              << lsf::formatMiddleburyLayout(layout) << "\nPer region (mean of scenes):\n\n"
              << lsf::formatMiddleburyRegions(layout) << "\n"
              << kEdgeSidesTitle << lsf::formatEdgeSides(layout) << "\n";
  }
  std::cout << "Middlebury protocol: " << secondsSince(t) << " s\n\n";
}

/// A depth protocol's layouts: the method table, the depth bands and the regions, each the mean
/// over the layout's `items` (frames, seeds).
void printDepthLayouts(const std::vector<lsf::LayoutScores<lsf::DepthMetrics>>& layouts,
                       const std::string& items) {
  for (const auto& layout : layouts) {
    std::cout << "## " << layout.name << ": " << layout.description << "\n\n"
              << lsf::formatKittiLayout(layout) << "\nPer depth band (mean of " << items << "):\n\n"
              << lsf::formatDepthBands(layout) << "\nPer region (mean of " << items << "):\n\n"
              << lsf::formatKittiRegions(layout) << "\n"
              << kEdgeSidesTitle << lsf::formatEdgeSides(layout) << "\n";
  }
}

void printKitti(const lsf::AccuracyOptions& options) {
  const auto t = std::chrono::steady_clock::now();
  printDepthLayouts(lsf::runKittiProtocol(options), "frames");
  std::cout << "KITTI protocol: " << secondsSince(t) << " s"
            << (options.kitti_pms ? "" : " (without pms)") << "\n\n";
}

void printDense(const lsf::AccuracyOptions& options, const Options& o) {
  const auto t = std::chrono::steady_clock::now();
  lsf::kitti::AccumulationParams reference_params;
  reference_params.keep_unverified = o.keep_unverified;
  if (o.reference == "majority") {
    reference_params.combine = lsf::kitti::AccumulationParams::Combine::kMajority;
  }
  const lsf::DenseProtocolResult dense =
      lsf::runDenseProtocol(options, reference_params, o.stereo_check_px);
  std::cout << "## dense: " << dense.layout.description << "\n\n"
            << lsf::formatKittiLayout(dense.layout)
            << "\nPer depth band of the reference depth:\n\n"
            << lsf::formatDepthBands(dense.layout) << "\nPer region:\n\n"
            << lsf::formatKittiRegions(dense.layout) << "\n"
            << kEdgeSidesTitle << lsf::formatEdgeSides(dense.layout) << "\nThe reference:\n\n"
            << lsf::formatAccumulatedReference(dense.reference)
            << lsf::formatStereoCheck(dense.stereo_check, o.stereo_check_px) << "\n";
  std::cout << "Dense protocol: " << secondsSince(t) << " s"
            << (options.kitti_pms ? "" : " (without pms)") << "\n";
}

void printSynthetic(const lsf::AccuracyOptions& options) {
  const auto t = std::chrono::steady_clock::now();
  printDepthLayouts(lsf::runSyntheticDenseProtocol(options), "seeds");
  std::cout << "Synthetic dense protocol: " << secondsSince(t) << " s"
            << (options.kitti_pms ? "" : " (without pms)") << "\n";
}

int run(const Options& o) {
  // The synthetic street reads no data folder.
  if ((o.middlebury || o.kitti || o.dense) && !std::filesystem::is_directory(o.data)) {
    throw std::runtime_error("data folder not found: " + o.data +
                             " (pass --data <dir> or set LSF_DATA_DIR)");
  }
  const lsf::AccuracyOptions options = accuracyOptions(o);
  std::cout << "Scoring: empty pixels filled like the KITTI devkit's interpolateBackground "
               "(gaps in a row take the nearer neighbour), then scored; 'raw coverage' is before "
               "the fill. Regions: see eval/accuracy_protocols.h.\n\n";
  if (o.middlebury) printMiddlebury(options);
  if (o.kitti) printKitti(options);
  if (o.dense) printDense(options, o);
  if (o.synthetic) printSynthetic(options);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return lsf::toolMain("accuracy_report", kUsage, argc, argv,
                       [&] { return run(parseOptions(argc, argv)); });
}
