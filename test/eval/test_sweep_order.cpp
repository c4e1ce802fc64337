// The sweep with its order lost (eval/sweep_order.h), exact answers: the names, the shuffle as
// std::shuffle makes it, image-row order on hand-made points (ties by column, then storage order;
// points behind, outside and not finite after or dropped), and a shuffled multi-beam sweep whose
// rings come back as its generating beams.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "core/test_scenes.h"
#include "lidar_stereo_fusion/eval/sweep_order.h"

namespace lidar_stereo_fusion {
namespace {

LidarPoint at(double x, double y, double z, int ring = 0) {
  LidarPoint p;
  p.x = static_cast<float>(x);
  p.y = static_cast<float>(y);
  p.z = static_cast<float>(z);
  p.ring = ring;
  return p;
}

TEST(SweepOrder, NamesRoundTripAndAnUnknownOneIsNamed) {
  for (const SweepOrder o : {SweepOrder::kRecorded, SweepOrder::kShuffled, SweepOrder::kImageRows,
                             SweepOrder::kImageRowsCropped}) {
    EXPECT_EQ(parseSweepOrder(sweepOrderName(o)), o);
  }
  EXPECT_EQ(sweepOrderName(SweepOrder::kImageRowsCropped), "image-rows-cropped");
  try {
    parseSweepOrder("sorted");
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'sorted'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("image-rows-cropped"), std::string::npos) << e.what();
  }
}

TEST(SweepOrder, ShuffledIndicesAreStdShuffleOfTheIdentity) {
  std::vector<std::size_t> expected(1000);
  std::iota(expected.begin(), expected.end(), std::size_t{0});
  std::mt19937 rng(7);
  std::shuffle(expected.begin(), expected.end(), rng);
  const std::vector<std::size_t> got = shuffledIndices(1000, 7);
  EXPECT_EQ(got, expected);
  EXPECT_NE(got, shuffledIndices(1000, 8));
  EXPECT_TRUE(shuffledIndices(0, 7).empty());
}

TEST(SweepOrder, ImageRowsSortByRowThenColumnThenStorageWithTheRestAfterOrDropped) {
  // 200 x 100 px, f = 100, principal point (100, 50); the camera frame is the LiDAR's.
  const StereoCamera camera = test::centredCamera(200, 100, 100.0);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  LidarCloud cloud = {
      at(0, 0, 10),         // 0: row 50, column 100
      at(-5, -2.5, 10),     // 1: row 25, column 50
      at(0, 0, 0.3),        // 2: nearer than 0.5 m: outside
      at(5, 2.5, 10),       // 3: row 75, column 150
      at(-1, -0.5, 10),     // 4: row 45, column 90
      at(nan, 0, 10),       // 5: not finite: outside
      at(30, 0, 10),        // 6: column 400: outside
      at(-5, -2.5, 10),     // 7: the pixel of 1: after it
      at(-4.96, -2.5, 10),  // 8: column 50.4 rounds to 50, the pixel of 1 and 7
      at(-5.96, -2.5, 10),  // 9: column 40.4 -> 40: first in row 25
  };
  const Eigen::Isometry3d identity = Eigen::Isometry3d::Identity();
  EXPECT_EQ(imageRowIndices(cloud, identity, camera, false),
            (std::vector<std::size_t>{9, 1, 7, 8, 4, 0, 3, 2, 5, 6}));
  EXPECT_EQ(imageRowIndices(cloud, identity, camera, true),
            (std::vector<std::size_t>{9, 1, 7, 8, 4, 0, 3}));
  // The LiDAR 1 m left of the camera: its points land 10 px further left at 10 m.
  Eigen::Isometry3d shifted = identity;
  shifted.translation() = Eigen::Vector3d(-1, 0, 0);
  EXPECT_EQ(imageRowIndices({at(0.5, 0, 10), at(0, 0, 10)}, shifted, camera, true),
            (std::vector<std::size_t>{1, 0}));
}

TEST(SweepOrder, AShuffledMultiBeamSweepGetsItsBeamsBackAndRecordedStaysAsItIs) {
  // 8 beams, -15 .. +6 deg in 3 deg steps from one origin, 200 points each at 3-40 m, recorded
  // beam after beam in azimuth order; ring = beam index, the lowest first as ensureRings numbers.
  LidarCloud cloud;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int b = 0; b < 8; ++b) {
    const double tan_el = std::tan((-15.0 + 3.0 * b) * M_PI / 180.0);
    for (int k = 0; k < 200; ++k) {
      const double r = 3.0 * std::pow(40.0 / 3.0, unit(rng)), az = 2 * M_PI * k / 200.0;
      cloud.push_back(at(r * std::cos(az), r * std::sin(az), r * tan_el, b));
    }
  }
  const StereoCamera camera = test::centredCamera(200, 100, 100.0);
  const Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const ReorderedSweep recorded = reorderSweep(cloud, SweepOrder::kRecorded, T, camera, 64, 7);
  EXPECT_EQ(recorded.rings.rings, 8);
  ASSERT_EQ(recorded.cloud.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) EXPECT_EQ(recorded.cloud[i].ring, cloud[i].ring);

  const ReorderedSweep shuffled = reorderSweep(cloud, SweepOrder::kShuffled, T, camera, 64, 7);
  EXPECT_EQ(shuffled.rings.source, RingSource::kBeamModel) << shuffled.rings.fallbacks;
  EXPECT_EQ(shuffled.rings.rings, 8);
  const std::vector<std::size_t> order = shuffledIndices(cloud.size(), 7);
  ASSERT_EQ(shuffled.cloud.size(), cloud.size());
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    EXPECT_EQ(shuffled.cloud[i].x, cloud[order[i]].x);
    wrong += shuffled.cloud[i].ring != cloud[order[i]].ring;
  }
  EXPECT_EQ(wrong, 0u);
  EXPECT_THROW(reorderSweep(cloud, SweepOrder::kShuffled, T, camera, 0, 7), std::invalid_argument);
}

}  // namespace
}  // namespace lidar_stereo_fusion
