// Issue 31, exact answers: the beam model (core/ring_recovery.h) gives every point of a synthetic
// multi-beam sweep its generating beam: an HDL-64E-like sensor with two blocks of per-beam
// elevations and origin offsets (which elevation alone cannot separate), shuffled; beams whose
// points all lie at one range; a VLS-128-like sensor with one origin and 0.11 deg spacing. A cloud
// without scan lines (random directions, a Livox-like rosette) is recognised and gets elevation
// bands flagged implausible.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/ring_recovery.h"

namespace lidar_stereo_fusion {
namespace {

constexpr double kDeg = M_PI / 180.0;

struct Beam {
  double elevation_deg, offset_m;
};

/// HDL-64E-like beams, lowest first: lower block -24.8..-8.8 deg in 0.5 deg steps with origins
/// 0.116..0.126 m up, upper block -8.5..+1.8 deg in 1/3 deg steps at 0.198..0.209 m (as fitted on
/// KITTI). At r = 3 m the blocks' 0.08 m offset difference is 1.5 deg of elevation.
std::vector<Beam> hdl64Beams() {
  std::vector<Beam> beams;
  for (int i = 0; i < 32; ++i) beams.push_back({-24.8 + 0.5 * i, 0.116 + 0.0003 * i});
  for (int i = 0; i < 32; ++i) beams.push_back({-8.5 + i / 3.0, 0.198 + 0.00035 * i});
  return beams;
}

/// A point of `beam` at range r (from the spin axis) and azimuth az [rad], ring = beam index.
LidarPoint beamPoint(const Beam& beam, int index, double r, double az) {
  LidarPoint p;
  p.x = static_cast<float>(r * std::cos(az));
  p.y = static_cast<float>(r * std::sin(az));
  p.z = static_cast<float>(r * std::tan(beam.elevation_deg * kDeg) + beam.offset_m);
  p.ring = index;
  return p;
}

/// `per_beam` points per beam at ranges log-uniform in [r_min, r_max], shuffled with `seed`.
LidarCloud sweep(const std::vector<Beam>& beams, int per_beam, double r_min, double r_max,
                 unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  LidarCloud cloud;
  for (std::size_t b = 0; b < beams.size(); ++b) {
    for (int k = 0; k < per_beam; ++k) {
      const double r = r_min * std::pow(r_max / r_min, unit(rng));
      cloud.push_back(beamPoint(beams[b], static_cast<int>(b), r, 2 * M_PI * unit(rng)));
    }
  }
  std::shuffle(cloud.begin(), cloud.end(), rng);
  return cloud;
}

/// Runs the beam model on a copy of `cloud` (whose rings are the generating beams) and expects
/// every point back on its beam, ring 0 the lowest.
BeamModel expectExactBeams(const LidarCloud& cloud, int beams) {
  LidarCloud recovered = cloud;
  for (auto& p : recovered) p.ring = -1;
  const BeamModel model = recoverRingsByBeamModel(recovered, 2 * beams);
  EXPECT_EQ(model.problem, "");
  EXPECT_EQ(static_cast<int>(model.beams.size()), beams);
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) wrong += recovered[i].ring != cloud[i].ring;
  EXPECT_EQ(wrong, 0u) << "of " << cloud.size() << " points";
  EXPECT_DOUBLE_EQ(model.explained, 1.0);
  return model;
}

TEST(RingBeamModel, Hdl64LikeSweepShuffledGetsEveryPointsGeneratingBeam) {
  const std::vector<Beam> beams = hdl64Beams();
  const LidarCloud cloud = sweep(beams, 1500, 2.5, 80.0, /*seed=*/1);
  const BeamModel model = expectExactBeams(cloud, 64);
  ASSERT_EQ(model.beams.size(), 64u);
  for (std::size_t i = 0; i < beams.size(); ++i) {
    EXPECT_NEAR(model.beams[i].tan_elevation, std::tan(beams[i].elevation_deg * kDeg), 1e-5);
    EXPECT_NEAR(model.beams[i].offset, beams[i].offset_m, 1e-3);
    EXPECT_LT(model.beams[i].rms, 1e-5);  // float coordinates only
    EXPECT_EQ(model.beams[i].points, 1500);
  }
  // Elevation alone cannot: its bands mix the blocks' near and far points.
  LidarCloud by_elevation = cloud;
  recoverRingsByElevation(by_elevation, 64);
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) wrong += by_elevation[i].ring != cloud[i].ring;
  EXPECT_GT(wrong, cloud.size() / 10);
}

TEST(RingBeamModel, NoiseAndNonFinitePointsAndOrderChangeNothing) {
  const std::vector<Beam> beams = hdl64Beams();
  LidarCloud cloud = sweep(beams, 800, 2.5, 60.0, /*seed=*/2);
  std::mt19937 rng(2);
  std::normal_distribution<double> noise(0.0, 1e-4);  // z / r, KITTI's beams: 3e-5..9e-5 RMS
  for (auto& p : cloud) p.z += static_cast<float>(noise(rng) * std::hypot(p.x, p.y));
  LidarPoint bad;
  bad.x = std::numeric_limits<float>::quiet_NaN();
  bad.ring = -1;
  cloud.insert(cloud.begin() + 100, bad);
  cloud.push_back(bad);
  expectExactBeams(cloud, 64);
  LidarCloud reversed(cloud.rbegin(), cloud.rend());
  LidarCloud a = cloud, b = reversed;
  const BeamModel ma = recoverRingsByBeamModel(a, 128), mb = recoverRingsByBeamModel(b, 128);
  ASSERT_EQ(ma.beams.size(), mb.beams.size());
  for (std::size_t i = 0; i < ma.beams.size(); ++i) {
    EXPECT_NEAR(ma.beams[i].tan_elevation, mb.beams[i].tan_elevation, 1e-12);
    EXPECT_NEAR(ma.beams[i].offset, mb.beams[i].offset, 1e-9);
  }
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].ring, b[a.size() - 1 - i].ring);
  EXPECT_EQ(a[100].ring, -1);
  EXPECT_EQ(a.back().ring, -1);
}

// A flat road in front of the car: every beam pointing down meets it at one range, so its points
// do not tell its offset (any offset makes it one peak); the beams must still come back.
TEST(RingBeamModel, BeamsOnAFlatGroundAtOneRangeEachComeBack) {
  const std::vector<Beam> all = hdl64Beams();
  const std::vector<Beam> beams(all.begin(), all.begin() + 40);  // all below -6 deg
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> az(-0.7, 0.7);  // the camera's view
  LidarCloud cloud;
  for (std::size_t b = 0; b < beams.size(); ++b) {
    const double r = (-1.73 - beams[b].offset_m) / std::tan(beams[b].elevation_deg * kDeg);
    for (int k = 0; k < 300; ++k) cloud.push_back(beamPoint(beams[b], int(b), r, az(rng)));
  }
  std::shuffle(cloud.begin(), cloud.end(), rng);
  expectExactBeams(cloud, 40);
}

// One origin, 128 beams: 0.11 deg apart in the centre, wider at the edges (VLS-128-like).
TEST(RingBeamModel, Vls128LikeSweepWithOneOriginGetsEveryBeam) {
  std::vector<Beam> beams;
  double elevation = -25.0;
  for (int i = 0; i < 128; ++i) {
    beams.push_back({elevation, 0.0});
    elevation += std::abs(elevation + 5.0) < 7.0 ? 0.11 : 0.6;
  }
  const BeamModel model = expectExactBeams(sweep(beams, 400, 1.5, 100.0, /*seed=*/4), 128);
  for (const BeamLine& beam : model.beams) EXPECT_NEAR(beam.offset, 0.0, 1e-3);
}

// Beam lines that explain most but not 90 % of the points (a VoxelGrid's centroids near the
// sensor average neighbouring beams): still the best scan lines there are, used but flagged.
TEST(RingBeamModel, PointsBetweenTheBeamsGiveTheBeamsFlaggedImplausible) {
  const std::vector<Beam> beams = hdl64Beams();
  LidarCloud cloud = sweep(beams, 400, 2.5, 60.0, /*seed=*/8);
  std::vector<int> truth;
  for (const LidarPoint& p : cloud) truth.push_back(p.ring);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const std::size_t on_beams = cloud.size();
  for (std::size_t i = 0; i < on_beams / 4; ++i) {  // 1 in 5 points mixes two neighbouring beams
    const int b = static_cast<int>(unit(rng) * 63);
    const double r = 2.5 + 10 * unit(rng), az = 2 * M_PI * unit(rng), w = 0.3 + 0.4 * unit(rng);
    LidarPoint p = beamPoint(beams[b], -1, r, az);
    p.z = static_cast<float>((1 - w) * p.z + w * beamPoint(beams[b + 1], -1, r, az).z);
    cloud.push_back(p);
  }
  LidarCloud copy = cloud;
  const BeamModel model = recoverRingsByBeamModel(copy, 128);
  ASSERT_EQ(model.beams.size(), 64u);
  EXPECT_GT(model.explained, kMinScanLineExplained);
  EXPECT_LT(model.explained, kMinBeamModelExplained);
  const RingRecovery r = ensureRings(cloud, false, 64);
  EXPECT_EQ(r.source, RingSource::kBeamModel);
  EXPECT_EQ(r.rings, 64);
  EXPECT_FALSE(r.plausible);
  EXPECT_NE(r.fallbacks.find("beam model: the beam lines explain only 8"), std::string::npos)
      << r.fallbacks;
  std::size_t wrong = 0, changed = 0;
  for (std::size_t i = 0; i < on_beams; ++i) wrong += copy[i].ring != truth[i];
  for (std::size_t i = 0; i < cloud.size(); ++i) changed += cloud[i].ring != copy[i].ring;
  EXPECT_EQ(wrong, 0u) << "of " << on_beams << " points on the beams";
  EXPECT_EQ(changed, 0u);  // ensureRings used the model's rings
}

// A sweep in KITTI's order (laser after laser, the highest first, azimuth rising from just left of
// ahead round to just right of it) whose points in front are then sorted like image rows (top row
// first, each row left to right) and put first: the sweep order rule would still find 64
// plausible-looking rings, one of them holding every point in front. The azimuth stepping back
// within a ring gives it away; the beam model gets every beam.
TEST(RingBeamModel, ASweepOrderBrokenByImageRowSortingIsNotTakenForOne) {
  const std::vector<Beam> beams = hdl64Beams();
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  LidarCloud sweep_order;
  for (int b = 63; b >= 0; --b) {
    for (int k = 0; k < 600; ++k) {
      const double az = (0.3 + k * (360.0 - 0.6) / 600) * kDeg;
      sweep_order.push_back(beamPoint(beams[b], b, 3 + 50 * unit(rng), az));
    }
  }
  LidarCloud in_front, behind;
  for (const LidarPoint& p : sweep_order) {
    (std::abs(std::atan2(p.y, p.x)) < 45 * kDeg ? in_front : behind).push_back(p);
  }
  std::stable_sort(in_front.begin(), in_front.end(), [](const LidarPoint& a, const LidarPoint& b) {
    const double ea = std::atan2(a.z, std::hypot(a.x, a.y)),
                 eb = std::atan2(b.z, std::hypot(b.x, b.y));
    return std::round(ea / (0.2 * kDeg)) > std::round(eb / (0.2 * kDeg)) ||
           (std::round(ea / (0.2 * kDeg)) == std::round(eb / (0.2 * kDeg)) &&
            std::atan2(a.y, a.x) > std::atan2(b.y, b.x));
  });
  LidarCloud cloud = in_front;
  cloud.insert(cloud.end(), behind.begin(), behind.end());
  const LidarCloud truth = cloud;
  for (auto& p : cloud) p.ring = -1;
  const RingRecovery r = ensureRings(cloud, false, 64);
  EXPECT_EQ(r.source, RingSource::kBeamModel) << r.fallbacks;
  EXPECT_EQ(r.rings, 64);
  EXPECT_TRUE(r.plausible) << r.fallbacks;
  EXPECT_NE(r.fallbacks.find("of the points step back in azimuth (not in sweep order)"),
            std::string::npos)
      << r.fallbacks;
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) wrong += cloud[i].ring != truth[i].ring;
  EXPECT_EQ(wrong, 0u);
  // In its own order the sweep is the sweep order's.
  for (auto& p : sweep_order) p.ring = -1;
  EXPECT_EQ(ensureRings(sweep_order, false, 64).source, RingSource::kSweepOrder);
}

/// Directions of a Livox-like rosette (a rose curve turning slowly, 70 deg across) or uniformly
/// random in the same field of view; ranges 3..43 m.
LidarCloud noScanLines(bool rosette, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  LidarCloud cloud;
  for (int i = 0; i < n; ++i) {
    double az = (unit(rng) - 0.5) * 70 * kDeg, el = (unit(rng) - 0.5) * 70 * kDeg;
    if (rosette) {
      const double phi = 2 * M_PI * 1e-3 * i, turn = 2 * M_PI * 3e-6 * i;
      const double rho = 35 * kDeg * std::cos(3.5 * phi);
      az = rho * std::cos(phi + turn);
      el = rho * std::sin(phi + turn);
    }
    const double r = 3 + 40 * unit(rng);
    LidarPoint p;
    p.x = static_cast<float>(r * std::cos(el) * std::cos(az));
    p.y = static_cast<float>(r * std::cos(el) * std::sin(az));
    p.z = static_cast<float>(r * std::sin(el));
    cloud.push_back(p);
  }
  return cloud;
}

TEST(RingBeamModel, CloudsWithoutScanLinesGetElevationBandsFlaggedImplausible) {
  for (const bool rosette : {false, true}) {
    SCOPED_TRACE(rosette ? "rosette" : "random directions");
    LidarCloud cloud = noScanLines(rosette, 64000, 6);
    LidarCloud copy = cloud;
    const BeamModel model = recoverRingsByBeamModel(copy, 128);
    EXPECT_NE(model.problem, "");
    EXPECT_LT(model.explained, kMinBeamModelExplained);
    const RingRecovery r = ensureRings(cloud, false, 64);
    EXPECT_EQ(r.source, RingSource::kElevation);
    EXPECT_FALSE(r.plausible);
    EXPECT_EQ(r.rings, 64);
    EXPECT_NE(r.fallbacks.find("beam model: "), std::string::npos) << r.fallbacks;
    EXPECT_NE(r.fallbacks.find("elevation: no scan lines, 64 bands of equal point counts"),
              std::string::npos)
        << r.fallbacks;
    std::vector<int> count(64, 0);
    for (const LidarPoint& p : cloud) ++count.at(p.ring);
    for (const int c : count) EXPECT_EQ(c, 1000);
  }
}

TEST(RingBeamModel, ElevationBandsAreEqualCountsLowestFirst) {
  LidarCloud cloud;
  for (const double z : {3.0, -1.0, 2.0, 0.0, 1.0, -2.0}) {
    LidarPoint p;
    p.x = 10.f;
    p.z = static_cast<float>(z);
    cloud.push_back(p);
  }
  cloud[1].y = std::numeric_limits<float>::infinity();
  EXPECT_EQ(recoverRingsByElevationBands(cloud, 2), 2);
  const std::vector<int> expected = {1, -1, 1, 0, 0, 0};  // z -2, 0, 1 | 2, 3
  for (std::size_t i = 0; i < cloud.size(); ++i) EXPECT_EQ(cloud[i].ring, expected[i]) << i;
  EXPECT_EQ(recoverRingsByElevationBands(cloud, 10), 5);
  EXPECT_THROW(recoverRingsByElevationBands(cloud, 0), std::invalid_argument);
  EXPECT_THROW(recoverRingsByBeamModel(cloud, 0), std::invalid_argument);
  EXPECT_EQ(ringSourceName(RingSource::kBeamModel), "beam_model");
}

}  // namespace
}  // namespace lidar_stereo_fusion
