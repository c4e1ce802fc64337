// Middlebury 2003 cones and teddy (quarter size) with a pseudo-LiDAR sampled from the ground truth
// on 64 rows, 16 rows, and 42 rows over the lower 2/3 only (eval/accuracy_protocols.h), scored over
// every ground-truth pixel after the KITTI devkit's fill. On every layout (mean of the two scenes)
// the default fused method, and the live preset (config/live.yaml), must each have a lower MAE and
// a lower bad-2 rate than each of LiDAR-only BI*, plain PMS, "LiDAR-only else PMS" and the
// nearest-point fill, by a margin, also on the scenes turned upside down; and the paper preset must
// reproduce the fused_bi numbers of the package before confidence weighting. Above the LiDAR where
// both views see the pixel, both presets stay near plain PMS.
#include <filesystem>
#include <iostream>
#include <string>
#include <system_error>

#include <gtest/gtest.h>
#include <unistd.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "data/data_guard.h"
#include "lidar_stereo_fusion/eval/accuracy_protocols.h"
#include "lidar_stereo_fusion/eval/pseudo_lidar.h"
#include "lidar_stereo_fusion/io/middlebury.h"
#include "lidar_stereo_fusion/io/params_yaml.h"

namespace lidar_stereo_fusion {
namespace {

/// The fused method must beat every baseline by this fraction of the baseline's score.
constexpr double kMargin = 0.10;

const DisparityMetrics& all(const LayoutScores<DisparityMetrics>& layout, const std::string& m) {
  const MethodScores<DisparityMetrics>* scores = layout.find(m);
  if (!scores) throw std::runtime_error("method " + m + " did not run on " + layout.name);
  return scores->mean[static_cast<int>(Region::kAll)];
}

using Layouts = std::vector<LayoutScores<DisparityMetrics>>;

/// Both scenes turned upside down (images and ground truth, rows reversed: still a rectified
/// pair) in a temporary data folder, removed with the object: the lower 2/3's top third, where
/// stereo alone decides, is then another part of each scene, one nothing was tuned on.
class FlippedScenes {
 public:
  FlippedScenes()
      : root_(std::filesystem::temp_directory_path() /
              ("lsf_middlebury_flipped_" + std::to_string(::getpid()))) {
    for (const char* scene : {"cones", "teddy"}) {
      std::filesystem::create_directories(root_ / "middlebury" / scene);
      for (const char* file : {"im2.png", "im6.png", "disp2.png"}) {
        const std::string from = test::dataPath(std::string("middlebury/") + scene + "/" + file);
        const cv::Mat image = cv::imread(from, cv::IMREAD_UNCHANGED);
        if (image.empty()) throw std::runtime_error("cannot read " + from);
        cv::Mat flipped;
        cv::flip(image, flipped, 0);
        cv::imwrite((root_ / "middlebury" / scene / file).string(), flipped);
      }
    }
  }
  ~FlippedScenes() {
    std::error_code ignored;
    std::filesystem::remove_all(root_, ignored);
  }
  FlippedScenes(const FlippedScenes&) = delete;
  FlippedScenes& operator=(const FlippedScenes&) = delete;
  std::string dataDir() const { return root_.string(); }

 private:
  std::filesystem::path root_;
};

/// The default (or, with `live`, the live preset alone as the "fused" row) on the scenes in
/// `data_dir`, with the baselines.
Layouts run(const std::string& data_dir, bool live) {
  AccuracyOptions options;
  options.data_dir = data_dir;
  if (live) {
    loadParamsYaml(std::string(LSF_SOURCE_DIR) + "/config/live.yaml", options.fused);
    options.methods = {"fused"};
  } else {
    FusionParams paper;
    loadParamsYaml(std::string(LSF_SOURCE_DIR) + "/config/paper.yaml", paper);
    options.paper = paper;
    options.methods = {"fused", "paper", "lidar_bi", "pms", "lidar_bi else pms", "nearest"};
  }
  return runMiddleburyProtocol(options);
}

const Layouts& results() {
  static const Layouts layouts = run(LSF_DATA_DIR, false);
  return layouts;
}

/// The live preset as the "fused" row, alone.
const Layouts& liveResults() {
  static const Layouts layouts = run(LSF_DATA_DIR, true);
  return layouts;
}

const DisparityMetrics& liveScore(const Layouts& live_layouts, const std::string& name) {
  for (const auto& layout : live_layouts) {
    if (layout.name == name) return all(layout, "fused");
  }
  throw std::runtime_error("layout " + name + " did not run with the live preset");
}

void expectFusedBeatsEveryBaseline(const std::string& name, const Layouts& layouts = results(),
                                   const Layouts& live_layouts = liveResults()) {
  for (const auto& layout : layouts) {
    if (layout.name != name) continue;
    const DisparityMetrics& fused = all(layout, "fused");
    const DisparityMetrics& live = liveScore(live_layouts, name);
    std::cout << name << ": fused MAE " << fused.mae_px << " px, bad-2 " << 100 * fused.bad2
              << " %; live MAE " << live.mae_px << " px, bad-2 " << 100 * live.bad2 << " %\n";
    for (const char* baseline : {"lidar_bi", "pms", "lidar_bi else pms", "nearest"}) {
      const DisparityMetrics& b = all(layout, baseline);
      std::cout << "  " << baseline << ": MAE " << b.mae_px << " px, bad-2 " << 100 * b.bad2
                << " %\n";
      EXPECT_LT(fused.mae_px, (1 - kMargin) * b.mae_px) << name << " vs " << baseline;
      EXPECT_LT(fused.bad2, (1 - kMargin) * b.bad2) << name << " vs " << baseline;
      EXPECT_LT(live.mae_px, (1 - kMargin) * b.mae_px) << name << ": live vs " << baseline;
      EXPECT_LT(live.bad2, (1 - kMargin) * b.bad2) << name << ": live vs " << baseline;
    }
    return;
  }
  FAIL() << "layout " << name << " did not run";
}

TEST(Middlebury, FusedBeatsEveryBaselineWith64Rows) {
  LSF_REQUIRE_DATA("middlebury/cones");
  LSF_REQUIRE_DATA("middlebury/teddy");
  expectFusedBeatsEveryBaseline("mb64");
}

TEST(Middlebury, FusedBeatsEveryBaselineWith16Rows) {
  LSF_REQUIRE_DATA("middlebury/cones");
  LSF_REQUIRE_DATA("middlebury/teddy");
  expectFusedBeatsEveryBaseline("mb16");
}

TEST(Middlebury, FusedBeatsEveryBaselineWithRowsInTheLowerTwoThirdsOnly) {
  LSF_REQUIRE_DATA("middlebury/cones");
  LSF_REQUIRE_DATA("middlebury/teddy");
  expectFusedBeatsEveryBaseline("mb42low");
}

// The same orderings on the scenes turned upside down, on every layout. Where `live` searched
// these small images at 1/4 and 1/2 size only, it lost the lower 2/3's bad-2 rate to "LiDAR-only
// else PMS" there (6.40 against 6.37 % at seed 42); with the full search (full_search_pixels) it
// has 4.71 % (doc/performance.md).
TEST(Middlebury, FusedBeatsEveryBaselineOnTheScenesUpsideDown) {
  LSF_REQUIRE_DATA("middlebury/cones");
  LSF_REQUIRE_DATA("middlebury/teddy");
  const FlippedScenes scenes;
  const Layouts flipped = run(scenes.dataDir(), false);
  const Layouts flipped_live = run(scenes.dataDir(), true);
  for (const char* name : {"mb64", "mb16", "mb42low"}) {
    expectFusedBeatsEveryBaseline(name, flipped, flipped_live);
  }
}

// Above the LiDAR (the lower 2/3's top third), where both images see the pixel (region "above,
// both views": the left border band the right image does not see is left out), only stereo
// decides. There the default, which searches it at full size, must stay within 15 % of plain PMS
// (0.348 against 0.330 px at seed 42), and so must `live`: these images are below its
// full_search_pixels, so it searches them as the default does (cut to 1/4 and 1/2 size it had
// 0.457 px; doc/accuracy.md).
TEST(Middlebury, AboveTheLidarWhereBothViewsSeeThePixelStereoStaysNearPlainPms) {
  LSF_REQUIRE_DATA("middlebury/cones");
  LSF_REQUIRE_DATA("middlebury/teddy");
  const auto region = [](const LayoutScores<DisparityMetrics>& layout, const std::string& m) {
    const MethodScores<DisparityMetrics>* scores = layout.find(m);
    if (!scores) throw std::runtime_error("method " + m + " did not run on " + layout.name);
    return scores->mean[static_cast<int>(Region::kAboveBothViews)];
  };
  for (const auto& layout : results()) {
    if (layout.name != "mb42low") continue;
    const DisparityMetrics pms = region(layout, "pms");
    const DisparityMetrics fused = region(layout, "fused");
    ASSERT_GT(pms.count, 0);
    EXPECT_LT(fused.mae_px, 1.15 * pms.mae_px);
    for (const auto& live_layout : liveResults()) {
      if (live_layout.name != "mb42low") continue;
      const DisparityMetrics live = region(live_layout, "fused");
      EXPECT_EQ(live.count, pms.count);
      EXPECT_LT(live.mae_px, 1.15 * pms.mae_px);
      std::cout << "above, both views: fused " << fused.mae_px << " px, live " << live.mae_px
                << " px, pms " << pms.mae_px << " px\n";
      return;
    }
  }
  FAIL() << "mb42low did not run";
}

// The fused_bi numbers of the package before confidence weighting (same protocol, devkit fill),
// which config/paper.yaml must reproduce within 1 %.
TEST(Middlebury, PaperPresetReproducesThePreviousFusedNumbers) {
  LSF_REQUIRE_DATA("middlebury/cones");
  LSF_REQUIRE_DATA("middlebury/teddy");
  struct Reference {
    const char* layout;
    double mae_px, bad2;
  };
  for (const Reference& ref : {Reference{"mb64", 0.223, 0.0273}, Reference{"mb16", 1.026, 0.1285},
                               Reference{"mb42low", 1.428, 0.1522}}) {
    for (const auto& layout : results()) {
      if (layout.name != ref.layout) continue;
      const DisparityMetrics& paper = all(layout, "paper");
      EXPECT_NEAR(paper.mae_px, ref.mae_px, 0.01 * ref.mae_px) << ref.layout;
      EXPECT_NEAR(paper.bad2, ref.bad2, 0.01 * ref.bad2) << ref.layout;
    }
  }
}

// Middlebury's ground truth, made by the cameras, puts a boundary pixel on the far surface unless
// it is mostly the near one; the mixed edge step (core/mixed_edges.h) at its default 0.75 leaves
// every layout as it was (measured: within 0.3 %; at 0.35 mb64 loses 12 %, doc/accuracy.md).
TEST(Middlebury, TheMixedEdgeStepLeavesEveryLayoutAsItWas) {
  LSF_REQUIRE_DATA("middlebury/cones");
  LSF_REQUIRE_DATA("middlebury/teddy");
  AccuracyOptions options;
  options.data_dir = LSF_DATA_DIR;
  options.methods = {"fused"};
  ASSERT_EQ(options.fused.patchmatch.mixed_edge_fraction, 0.75);
  options.fused.patchmatch.mixed_edge_fraction = 0.0;
  const Layouts without = runMiddleburyProtocol(options);
  for (const auto& layout : results()) {
    for (const auto& off : without) {
      if (off.name != layout.name) continue;
      const DisparityMetrics& on = all(layout, "fused");
      const DisparityMetrics& o = all(off, "fused");
      std::cout << layout.name << ": MAE " << o.mae_px << " -> " << on.mae_px << " px, bad-2 "
                << 100 * o.bad2 << " -> " << 100 * on.bad2 << " %\n";
      EXPECT_LE(on.mae_px, 1.01 * o.mae_px) << layout.name;
      EXPECT_LE(on.bad2, 1.01 * o.bad2) << layout.name;
    }
  }
}

TEST(Middlebury, PseudoLidarRowsAreExactGroundTruthSamples) {
  LSF_REQUIRE_DATA("middlebury/cones");
  const MiddleburyScene scene = readMiddleburyScene(test::dataPath("middlebury/cones"));
  ASSERT_EQ(scene.left.size(), cv::Size(450, 375));
  const SparseDisparity sparse = sampleRowsAsScanLines(scene.disparity, 64);
  int rows_with_samples = 0;
  for (int y = 0; y < sparse.disparity.rows; ++y) {
    int samples = 0;
    for (int x = 0; x < sparse.disparity.cols; ++x) {
      if (sparse.disparity(y, x) > 0) {
        ++samples;
        ASSERT_EQ(sparse.disparity(y, x), scene.disparity(y, x));
        ASSERT_EQ(sparse.ring(y, x), rows_with_samples);
      }
    }
    rows_with_samples += samples > 0;
  }
  EXPECT_EQ(rows_with_samples, 64);
}

}  // namespace
}  // namespace lidar_stereo_fusion
