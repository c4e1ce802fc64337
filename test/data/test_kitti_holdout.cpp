// Ring hold-out on the real KITTI drive (eval/accuracy_protocols.h): 32 rings fed (ring % 2 == 0)
// and 16 rings fed (ring % 4 == 0), every other ring's points the reference depth, 11 frames, empty
// pixels filled like the KITTI devkit before scoring. The default fused method and the live preset
// (config/live.yaml) must each have a lower MAE and a lower >3 px rate than LiDAR-only BI* on
// both, by a margin; the paper preset must reproduce the fused_bi numbers of the package before
// confidence weighting.
//
// Plain PMS (~50 s per frame on 2 cores) is left to the accuracy_report tool.
#include <iostream>

#include <gtest/gtest.h>

#include "data/data_guard.h"
#include "lidar_stereo_fusion/eval/accuracy_protocols.h"
#include "lidar_stereo_fusion/io/params_yaml.h"

namespace lidar_stereo_fusion {
namespace {

const char* const kDrive = "kitti_raw/2011_09_26/2011_09_26_drive_0009_sync";
constexpr double kMargin = 0.05;  ///< fused must beat lidar_bi by this fraction

const DepthMetrics& all(const LayoutScores<DepthMetrics>& layout, const std::string& m) {
  const MethodScores<DepthMetrics>* scores = layout.find(m);
  if (!scores) throw std::runtime_error("method " + m + " did not run on " + layout.name);
  return scores->mean[static_cast<int>(Region::kAll)];
}

TEST(KittiHoldout, FusedBeatsLidarOnlyOn32And16RingsAndThePaperPresetReproducesItsNumbers) {
  LSF_REQUIRE_DATA(kDrive);
  AccuracyOptions options;
  options.data_dir = LSF_DATA_DIR;
  FusionParams paper;
  loadParamsYaml(std::string(LSF_SOURCE_DIR) + "/config/paper.yaml", paper);
  options.paper = paper;
  options.methods = {"fused", "paper", "lidar_bi"};
  options.kitti_pms = false;
  const auto layouts = runKittiProtocol(options);
  ASSERT_EQ(layouts.size(), 2u);
  struct Reference {
    double mae_mm, bad3;  // fused_bi before confidence weighting
  };
  const Reference previous[2] = {{1150, 0.0788}, {1546, 0.1165}};
  for (size_t i = 0; i < layouts.size(); ++i) {
    const auto& layout = layouts[i];
    ASSERT_EQ(layout.items.size(), 11u);
    const DepthMetrics& fused = all(layout, "fused");
    const DepthMetrics& lidar = all(layout, "lidar_bi");
    const DepthMetrics& old = all(layout, "paper");
    std::cout << layout.name << ": fused MAE " << fused.mae_mm << " mm, >3 px " << 100 * fused.bad3
              << " %; lidar_bi " << lidar.mae_mm << " mm, " << 100 * lidar.bad3 << " %; paper "
              << old.mae_mm << " mm, " << 100 * old.bad3 << " %\n";
    EXPECT_LT(fused.mae_mm, (1 - kMargin) * lidar.mae_mm) << layout.name;
    EXPECT_LT(fused.bad3, (1 - kMargin) * lidar.bad3) << layout.name;
    EXPECT_NEAR(old.mae_mm, previous[i].mae_mm, 0.01 * previous[i].mae_mm) << layout.name;
    EXPECT_NEAR(old.bad3, previous[i].bad3, 0.01 * previous[i].bad3) << layout.name;
  }
}

TEST(KittiHoldout, TheLivePresetBeatsLidarOnlyOn32And16Rings) {
  LSF_REQUIRE_DATA(kDrive);
  AccuracyOptions options;
  options.data_dir = LSF_DATA_DIR;
  options.methods = {"fused", "lidar_bi"};
  options.kitti_pms = false;
  loadParamsYaml(std::string(LSF_SOURCE_DIR) + "/config/live.yaml", options.fused);
  const auto layouts = runKittiProtocol(options);
  ASSERT_EQ(layouts.size(), 2u);
  for (const auto& layout : layouts) {
    const DepthMetrics& live = all(layout, "fused");
    const DepthMetrics& lidar = all(layout, "lidar_bi");
    std::cout << layout.name << ": live MAE " << live.mae_mm << " mm, >3 px " << 100 * live.bad3
              << " %; lidar_bi " << lidar.mae_mm << " mm, " << 100 * lidar.bad3 << " %\n";
    EXPECT_LT(live.mae_mm, (1 - kMargin) * lidar.mae_mm) << layout.name;
    EXPECT_LT(live.bad3, (1 - kMargin) * lidar.bad3) << layout.name;
  }
}

}  // namespace
}  // namespace lidar_stereo_fusion
