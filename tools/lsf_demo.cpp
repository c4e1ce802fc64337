// lsf_demo: the README demo. Runs the whole method on a synthetic street with exact ground truth
// (default) or on the KITTI sample (--kitti, scored on held-out LiDAR rings), prints a table of
// metrics per method and writes pictures a person can look at. Also generates the synthetic scene
// in the KITTI raw layout (--generate) for the offline runner.
//
//   lsf_demo [--out DIR] [--seed N] [--fast] [--rings 64|128] [--methods a,b,...]
//   lsf_demo --kitti [DRIVE_DIR] [--frame NAME] [--out DIR] [--fast] [--methods a,b,...]
//   lsf_demo --generate DIR [--seed N] [--frames N] [--rings 64|128] [--fast]
#include <unistd.h>

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

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lidar_stereo_fusion/core/metrics.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/io/holdout.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/simd_env.h"
#include "lidar_stereo_fusion/io/visualization.h"
#include "lidar_stereo_fusion/sim/kitti_export.h"
#include "lidar_stereo_fusion/sim/occlusion_truth.h"
#include "lidar_stereo_fusion/sim/synthetic_frame.h"

namespace lsf = lidar_stereo_fusion;
namespace fs = std::filesystem;

namespace {

constexpr const char* kKittiDrive = "shared/data/kitti_raw/2011_09_26/2011_09_26_drive_0009_sync";
constexpr int kFastWidth = 620, kFastHeight = 188;

void printUsage() {
  std::cout
      << "Usage:\n"
         "  lsf_demo [--out DIR] [--seed N] [--fast] [--rings 64|128] [--methods a,b,...]\n"
         "      synthetic street with exact ground truth (default)\n"
         "  lsf_demo --kitti [DRIVE_DIR] [--frame NAME] [--out DIR] [--fast] [--methods ...]\n"
         "      the KITTI sample, scored on held-out LiDAR rings (even rings in, odd rings out)\n"
         "  lsf_demo --generate DIR [--seed N] [--frames N] [--rings 64|128] [--fast]\n"
         "      writes the synthetic street in the KITTI raw layout (+ exact depth PNGs)\n"
         "Options:\n"
         "  --out DIR      pictures go here (default ./demo_output)\n"
         "  --seed N       scene seed (default 1)\n"
         "  --fast         half-size images (620x188) for a quick look\n"
         "  --methods L    comma-separated subset of fused_bi,fused_bf,lidar_bi,lidar_bf,pms\n";
}

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
    if (!name.empty()) methods.push_back(lsf::parseMethod(name));
  }
  if (methods.empty()) throw std::invalid_argument("--methods needs at least one method");
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
    throw std::invalid_argument(flag + " needs an integer in [" + std::to_string(lo) + ", " +
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
      if (!next_is_value) throw std::invalid_argument(a + " needs a value");
      return args[++i];
    };
    if (a == "--help" || a == "-h") {
      printUsage();
      std::exit(0);
    } else if (a == "--kitti") {
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
      throw std::invalid_argument("unknown argument '" + a + "' (try --help)");
    }
  }
  return o;
}

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// ------------------------------------------------------------------------------------------------
// One case to run: images, the cloud fed to the method and the reference to score against.
// ------------------------------------------------------------------------------------------------

struct DemoCase {
  std::string title;
  lsf::FusionInput input;
  cv::Mat1f reference_depth;  ///< [m], 0 = no value (dense GT or held-out rings)
  bool dense_reference = false;
  /// An extra region scored separately (synthetic: the LiDAR's field of view, the dark van).
  struct Region {
    std::string column;       ///< table column title
    std::string description;  ///< what the region is
    cv::Mat1b mask;           ///< 255 inside
  };
  std::vector<Region> regions;
};

struct MethodRun {
  lsf::Method method;
  lsf::FusionResult result;
  lsf::DepthMetrics all;
  std::vector<lsf::DepthMetrics> regions;  ///< one per DemoCase::regions
};

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
// Pictures
// ------------------------------------------------------------------------------------------------

const MethodRun* findRun(const std::vector<MethodRun>& runs, lsf::Method m) {
  for (const MethodRun& r : runs) {
    if (r.method == m) return &r;
  }
  return nullptr;
}

/// A picture with a caption band above it, scaled to `width`.
cv::Mat captioned(const cv::Mat& image, const std::string& caption, int width) {
  cv::Mat scaled;
  const double s = static_cast<double>(width) / image.cols;
  cv::resize(image, scaled, cv::Size(width, static_cast<int>(std::lround(image.rows * s))), 0, 0,
             s < 1 ? cv::INTER_AREA : cv::INTER_NEAREST);
  constexpr int kBand = 22;
  cv::Mat out(scaled.rows + kBand, width, CV_8UC3, cv::Scalar(30, 30, 30));
  scaled.copyTo(out(cv::Rect(0, kBand, width, scaled.rows)));
  cv::putText(out, caption, cv::Point(6, 16), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              cv::Scalar(235, 235, 235), 1, cv::LINE_AA);
  return out;
}

/// Tiles in rows of two.
cv::Mat composite(const std::vector<std::pair<cv::Mat, std::string>>& tiles, int tile_width) {
  std::vector<cv::Mat> rows;
  for (size_t i = 0; i < tiles.size(); i += 2) {
    cv::Mat a = captioned(tiles[i].first, tiles[i].second, tile_width);
    cv::Mat b = i + 1 < tiles.size()
                    ? captioned(tiles[i + 1].first, tiles[i + 1].second, tile_width)
                    : cv::Mat(a.size(), a.type(), cv::Scalar(30, 30, 30));
    cv::Mat row;
    cv::hconcat(std::vector<cv::Mat>{a, cv::Mat(a.rows, 4, CV_8UC3, cv::Scalar(0, 0, 0)), b}, row);
    rows.push_back(row);
    rows.push_back(cv::Mat(4, row.cols, CV_8UC3, cv::Scalar(0, 0, 0)));
  }
  rows.pop_back();
  cv::Mat out;
  cv::vconcat(rows, out);
  return out;
}

/// Absolute disparity error at sparse reference pixels, drawn as dots over the darkened image.
cv::Mat errorDots(const cv::Mat& image, const cv::Mat1f& estimate, const cv::Mat1f& reference,
                  double max_error) {
  cv::Mat canvas;
  image.convertTo(canvas, -1, 0.4);
  const cv::Mat colours = lsf::colorizeError(estimate, reference, max_error);
  for (int y = 0; y < reference.rows; ++y) {
    for (int x = 0; x < reference.cols; ++x) {
      if (!(reference(y, x) > 0.f)) continue;
      const cv::Vec3b c = colours.at<cv::Vec3b>(y, x);
      cv::circle(canvas, cv::Point(x, y), 1, cv::Scalar(c[0], c[1], c[2]), cv::FILLED);
    }
  }
  return canvas;
}

void writeImage(const fs::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image)) {
    throw std::runtime_error("cannot write " + path.string());
  }
}

/// Writes the pictures; returns the composite's path.
fs::path writePictures(const DemoCase& c, const std::vector<MethodRun>& runs, const fs::path& out) {
  fs::create_directories(out);
  const lsf::StereoCamera& cam = c.input.camera;
  const cv::Mat1f reference = lsf::depthToDisparity(c.reference_depth, cam);
  double max_d = 0.0;
  cv::minMaxLoc(reference, nullptr, &max_d);
  constexpr double kMaxError = 4.0;  // [px]
  auto error = [&](const cv::Mat1f& estimate) {
    return c.dense_reference ? lsf::colorizeError(estimate, reference, kMaxError)
                             : errorDots(c.input.left, estimate, reference, kMaxError);
  };

  std::vector<std::pair<cv::Mat, std::string>> tiles;  // the composite: rows of two
  auto add = [&](const std::string& file, const cv::Mat& image, const std::string& caption,
                 bool in_composite = true) {
    writeImage(out / file, image);
    if (in_composite) tiles.emplace_back(image, caption);
  };
  add("left.png", c.input.left, "left image");
  add("reference.png",
      c.dense_reference ? lsf::colorizeDisparity(reference, max_d)
                        : lsf::overlaySparse(c.input.left, reference, max_d),
      c.dense_reference ? "exact ground-truth disparity" : "held-out LiDAR rings (reference)");
  if (!runs.empty()) {
    add("lidar_overlay.png",
        lsf::overlaySparse(c.input.left, runs.front().result.sparse.disparity, max_d),
        c.dense_reference ? "LiDAR projected into the left image"
                          : "LiDAR fed to the method (even rings)");
  }
  if (const MethodRun* r = findRun(runs, lsf::Method::kFusedBI)) {
    add("prior_bi.png", lsf::colorizeDisparity(r->result.prior, max_d), "BI* up-sampled LiDAR");
    add("prior_confidence.png", lsf::colorizeConfidence(r->result.confidence, r->result.prior),
        "confidence of the prior (dark 0 .. yellow 1)");
  }
  for (lsf::Method m : {lsf::Method::kFusedBI, lsf::Method::kPlainPMS, lsf::Method::kFusedBF}) {
    const MethodRun* r = findRun(runs, m);
    if (!r) continue;
    const std::string name = lsf::methodName(m);
    add(name + "_disparity.png", lsf::colorizeDisparity(r->result.disparity, max_d),
        m == lsf::Method::kPlainPMS ? "PMS (stereo only) disparity" : name + " disparity",
        m != lsf::Method::kFusedBF);
  }
  for (lsf::Method m : {lsf::Method::kFusedBI, lsf::Method::kPlainPMS}) {
    const MethodRun* r = findRun(runs, m);
    if (!r) continue;
    const std::string name = lsf::methodName(m);
    add(name + "_error.png", error(r->result.disparity),
        name + " disparity error (blue 0 .. red " + std::to_string(static_cast<int>(kMaxError)) +
            "+ px)");
  }
  const fs::path composite_path = out / "composite.png";
  writeImage(composite_path, composite(tiles, std::min(620, cam.width)));
  return composite_path;
}

// ------------------------------------------------------------------------------------------------
// Synthetic and KITTI cases
// ------------------------------------------------------------------------------------------------

lsf::sim::SyntheticParams syntheticParams(const Options& o) {
  lsf::sim::SyntheticParams p;
  p.seed = o.seed;
  p.rings = o.rings;
  return o.fast ? p.resized(kFastWidth, kFastHeight) : p;
}

/// Algorithm 1 on the synthetic frame, scored against the exact visibility flags.
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

DemoCase syntheticCase(const Options& o, lsf::sim::SyntheticFrame* frame_out) {
  const lsf::sim::SyntheticParams p = syntheticParams(o);
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

DemoCase kittiCase(const Options& o) {
  const std::string drive = findKittiDrive(o.kitti_dir);
  const lsf::kitti::Calibration calib =
      lsf::kitti::readCalibration(lsf::kitti::calibrationDirOf(drive));
  const std::vector<lsf::kitti::Frame> frames = lsf::kitti::listFrames(drive);
  if (frames.empty()) throw std::runtime_error("no complete frame in " + drive);
  auto it = frames.begin();
  if (!o.frame.empty()) {
    it = std::find_if(frames.begin(), frames.end(),
                      [&](const lsf::kitti::Frame& f) { return f.name == o.frame; });
    if (it == frames.end()) throw std::runtime_error("no frame " + o.frame + " in " + drive);
  }
  const lsf::kitti::FrameData data = lsf::kitti::loadFrame(*it, calib.camera);
  DemoCase c;
  c.title = "KITTI " + fs::path(drive).filename().string() + " frame " + it->name +
            ": even rings in, odd rings as reference";
  c.input.left = data.left;
  c.input.right = data.right;
  c.input.T_cam_lidar = calib.T_cam_velo;
  c.input.camera = calib.camera;
  if (o.fast) halveCase(c.input);
  const lsf::HoldoutCase holdout = lsf::makeRingHoldout(
      data.cloud, calib.T_cam_velo, c.input.camera, lsf::FusionParams().projection);
  c.input.cloud = holdout.fed;
  c.reference_depth = holdout.reference_depth;
  std::printf("KITTI %s frame %s (%dx%d): %zu points, %zu fed (even rings), %d reference pixels\n",
              drive.c_str(), it->name.c_str(), c.input.camera.width, c.input.camera.height,
              data.cloud.size(), holdout.fed.size(), cv::countNonZero(holdout.reference_depth));
  return c;
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
  const DemoCase c = synthetic ? syntheticCase(o, &frame) : kittiCase(o);
  if (synthetic) printOcclusionScore(frame);
  const std::vector<MethodRun> runs = runMethods(c, o.methods);
  printTable(c, runs);
  const fs::path composite = writePictures(c, runs, o.out);
  std::printf("\nPictures written to %s\n  (overview: %s)\n",
              fs::absolute(o.out).lexically_normal().c_str(),
              fs::absolute(composite).lexically_normal().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options o = parseOptions(argc, argv);
    if (o.rings != 64 && o.rings != 128) throw std::invalid_argument("--rings must be 64 or 128");
    if (o.mode == Options::Mode::kGenerate) return generate(o);
    return runDemo(o);
  } catch (const std::exception& e) {
    std::cerr << "lsf_demo: " << e.what() << "\n";
    return 1;
  }
}
