// The accuracy protocols (eval/accuracy_protocols.h) on the real data, with the fast methods only
// (lidar_bi and nearest; PatchMatch rows are the accuracy_report tool's job): layouts feed exactly
// the stated rows / rings, the devkit fill leaves no reference pixel empty, the regions partition
// the reference pixels, and LiDAR-only BI* is accurate on the dense 64-row pseudo-LiDAR.
// Which method wins is asserted elsewhere (test_middlebury.cpp, test_kitti_holdout.cpp).
#include <cmath>

#include <gtest/gtest.h>

#include "data/data_guard.h"
#include "lidar_stereo_fusion/eval/accuracy_protocols.h"
#include "lidar_stereo_fusion/io/middlebury.h"

namespace lidar_stereo_fusion {
namespace {

AccuracyOptions fastOptions() {
  AccuracyOptions options;
  options.data_dir = LSF_DATA_DIR;
  options.methods = {"lidar_bi", "nearest"};
  return options;
}

template <typename Metrics>
const Metrics& region(const MethodScores<Metrics>& m, Region r) {
  return m.mean[static_cast<int>(r)];
}

/// above + inside and edge + elsewhere partition the scored pixels; "above, both views" is part
/// of "above".
template <typename Metrics>
void expectRegionsPartition(const MethodScores<Metrics>& m, const std::string& layout) {
  EXPECT_LE(region(m, Region::kAboveBothViews).count, region(m, Region::kAbove).count)
      << layout << " " << m.name;
  EXPECT_EQ(region(m, Region::kAbove).count + region(m, Region::kInside).count,
            region(m, Region::kAll).count)
      << layout << " " << m.name;
  EXPECT_EQ(region(m, Region::kEdge).count + region(m, Region::kElsewhere).count,
            region(m, Region::kInside).count)
      << layout << " " << m.name;
  EXPECT_GT(region(m, Region::kEdge).count, 0) << layout << " " << m.name;
}

TEST(AccuracyProtocols, MiddleburyLayoutsFullCoverageAfterTheFillAndAccurateLidarBI) {
  LSF_REQUIRE_DATA("middlebury/cones");
  LSF_REQUIRE_DATA("middlebury/teddy");
  const auto layouts = runMiddleburyProtocol(fastOptions());
  ASSERT_EQ(layouts.size(), 3u);
  for (const auto& layout : layouts) {
    ASSERT_EQ(layout.items.size(), 2u) << layout.name;
    ASSERT_EQ(layout.methods.size(), 2u) << layout.name;
    for (const auto& m : layout.methods) {
      EXPECT_EQ(region(m, Region::kAll).coverage, 1.0) << layout.name << " " << m.name;
      expectRegionsPartition(m, layout.name);
    }
  }
  const auto* mb64 = layouts[0].find("lidar_bi");
  ASSERT_NE(mb64, nullptr);
  EXPECT_LT(region(*mb64, Region::kAll).mae_px, 0.5);
  // Nearest needs no fill: it covers every pixel itself.
  EXPECT_EQ(layouts[0].find("nearest")->raw_coverage, 1.0);
  // Sparser layouts leave more pixels above the LiDAR.
  const auto* low = layouts[2].find("lidar_bi");
  EXPECT_LT(region(*mb64, Region::kAbove).count, region(*low, Region::kAbove).count);
  // Above the lower 2/3, the left border band the right image does not see (x < d: up to 64
  // columns of 450) is left out of "above, both views", and the rest is kept.
  EXPECT_LT(region(*low, Region::kAboveBothViews).count, region(*low, Region::kAbove).count);
  EXPECT_GT(region(*low, Region::kAboveBothViews).count,
            region(*low, Region::kAbove).count * 8 / 10);
}

TEST(AccuracyProtocols, MiddleburyLowerTwoThirdsLayoutFeedsExactlyTheStatedRows) {
  LSF_REQUIRE_DATA("middlebury/cones");
  AccuracyOptions options = fastOptions();
  options.layouts = {"mb42low"};
  options.methods = {"nearest"};
  const auto layouts = runMiddleburyProtocol(options);
  ASSERT_EQ(layouts.size(), 1u);
  const MiddleburyScene cones = readMiddleburyScene(LSF_DATA_DIR "/middlebury/cones");
  const int h = cones.disparity.rows, first = h / 3;
  std::vector<int> expected;
  for (int k = 0; k < 42; ++k) {
    expected.push_back(first + static_cast<int>(std::floor((k + 0.5) * (h - first) / 42)));
  }
  EXPECT_EQ(layouts[0].fed_rows, expected);
  EXPECT_GE(layouts[0].fed_rows.front(), h / 3);
  EXPECT_EQ(layouts[0].fed_rings, (std::vector<int>{42, 42}));
}

TEST(AccuracyProtocols, KittiRingLayoutsFeedThirtyTwoAndSixteenRings) {
  LSF_REQUIRE_DATA("kitti_raw/2011_09_26/2011_09_26_drive_0009_sync");
  AccuracyOptions options = fastOptions();
  options.kitti_frames = 2;
  options.kitti_pms = false;
  const auto layouts = runKittiProtocol(options);
  ASSERT_EQ(layouts.size(), 2u);
  EXPECT_EQ(layouts[0].name, "ring32");
  EXPECT_EQ(layouts[0].fed_rings, (std::vector<int>{32, 32}));
  EXPECT_EQ(layouts[1].name, "ring16");
  EXPECT_EQ(layouts[1].fed_rings, (std::vector<int>{16, 16}));
  for (const auto& layout : layouts) {
    ASSERT_EQ(layout.items.size(), 2u);
    for (const auto& m : layout.methods) {
      EXPECT_EQ(region(m, Region::kAll).coverage, 1.0) << layout.name << " " << m.name;
      expectRegionsPartition(m, layout.name);
    }
    EXPECT_EQ(layout.find("nearest")->raw_coverage, 1.0);
  }
  // Fewer fed rings: more held-out reference pixels, and a coarser LiDAR-only result.
  EXPECT_GT(region(layouts[1].methods[0], Region::kAll).count,
            region(layouts[0].methods[0], Region::kAll).count);
  EXPECT_GT(region(*layouts[1].find("lidar_bi"), Region::kAll).mae_mm,
            region(*layouts[0].find("lidar_bi"), Region::kAll).mae_mm);
}

}  // namespace
}  // namespace lidar_stereo_fusion
