// Stages 1-2 on real data: ring recovery on every KITTI HDL-64E sweep and on a VLS-128 sweep,
// projection and BI* on KITTI frame 0000000000 with the real calibration. Tolerances, not exact
// answers; numbers are printed so that regressions show.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "data_guard.h"
#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/core/upsampling.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/pcd.h"

namespace lidar_stereo_fusion {
namespace {

const char* const kDrive = "kitti_raw/2011_09_26/2011_09_26_drive_0009_sync";
const char* const kVls128 = "vls128/1585897255376374245.pcd";

double elevationDeg(const LidarPoint& p) {
  return std::atan2(p.z, std::hypot(p.x, p.y)) * 180.0 / M_PI;
}

TEST(KittiRings, EverySweepHasExactly64RingsTopToBottom) {
  LSF_REQUIRE_DATA(kDrive);
  const std::filesystem::path dir = test::dataPath(kDrive) + "/velodyne_points/data";
  std::vector<std::string> sweeps;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() == ".bin") sweeps.push_back(entry.path().string());
  }
  std::sort(sweeps.begin(), sweeps.end());
  ASSERT_GE(sweeps.size(), 11u);
  for (const std::string& path : sweeps) {
    SCOPED_TRACE(path);
    LidarCloud cloud = kitti::readVelodyneBin(path);
    ASSERT_EQ(recoverRingsBySweepOrder(cloud), 64);
    std::vector<int> count(64, 0);
    std::vector<double> elevation(64, 0.0);
    for (const LidarPoint& p : cloud) {
      ++count[p.ring];
      elevation[p.ring] += elevationDeg(p);
    }
    for (int r = 0; r < 64; ++r) {
      // ~2000 per laser; the lowest lasers lose many returns to the car body (739 on frame 5).
      EXPECT_GT(count[r], 500) << "ring " << r;
      EXPECT_LT(count[r], 2500) << "ring " << r;
      elevation[r] /= count[r];
    }
    // Storage order is top to bottom: mean elevation from about +3 deg down to about -24 deg.
    EXPECT_GT(elevation[0], 2.0);
    EXPECT_LT(elevation[63], -22.0);
    for (int r = 1; r < 64; ++r) EXPECT_LT(elevation[r], elevation[r - 1]) << "ring " << r;
  }
}

TEST(Vls128Rings, ElevationClustersGiveOneRingPerFiringBeam) {
  LSF_REQUIRE_DATA(kVls128);
  LidarCloud cloud = pcd::readPcd(test::dataPath(kVls128));
  ASSERT_EQ(cloud.size(), 208680u);
  EXPECT_FALSE(hasRings(cloud));
  const int rings = recoverRingsByElevation(cloud, 128);
  // The VLS-128 has 128 beams, but in this sweep the beam at -5.40 deg (laser 82 of the
  // velodyne_pointcloud VLS128.yaml table) returned no point: the decoded cloud holds 127
  // distinct elevations (-5.51 deg is followed directly by -5.29 deg). A 128th ring would have to
  // be invented by splitting a real beam.
  EXPECT_EQ(rings, 127);
  std::vector<int> count(rings, 0);
  std::vector<double> lo(rings, 90.0), hi(rings, -90.0);
  for (const LidarPoint& p : cloud) {
    ASSERT_GE(p.ring, 0);
    ASSERT_LT(p.ring, rings);
    ++count[p.ring];
    lo[p.ring] = std::min(lo[p.ring], elevationDeg(p));
    hi[p.ring] = std::max(hi[p.ring], elevationDeg(p));
  }
  const double mean = static_cast<double>(cloud.size()) / rings;
  for (int r = 0; r < rings; ++r) {
    EXPECT_GT(count[r], 0.5 * mean) << "ring " << r;
    EXPECT_LT(count[r], 1.5 * mean) << "ring " << r;
    EXPECT_LT(hi[r] - lo[r], 0.05) << "ring " << r << " spans several beams";
    if (r > 0) {
      EXPECT_GT(lo[r] - hi[r - 1], 0.08) << "rings " << r - 1 << ", " << r;
    }
  }
  EXPECT_NEAR(lo[0], -25.0, 0.05);
  EXPECT_NEAR(hi[rings - 1], 15.0, 0.05);
}

/// Fraction of pixels, in columns with at least two scan lines, between the top and the bottom
/// line that have a value in `dense`.
double coverageBetweenLines(const cv::Mat1f& lines, const cv::Mat1f& dense) {
  long covered = 0, total = 0;
  for (int x = 0; x < lines.cols; ++x) {
    int top = -1, bottom = -1;
    for (int y = 0; y < lines.rows; ++y) {
      if (lines(y, x) > 0.f) {
        if (top < 0) top = y;
        bottom = y;
      }
    }
    if (top < 0 || bottom == top) continue;
    for (int y = top; y <= bottom; ++y) {
      ++total;
      if (dense(y, x) > 0.f) ++covered;
    }
  }
  return total > 0 ? static_cast<double>(covered) / total : 0.0;
}

class KittiFrame0 : public ::testing::Test {
 protected:
  void SetUp() override {
    LSF_REQUIRE_DATA(kDrive);
    const std::string drive = test::dataPath(kDrive);
    calibration_ = kitti::readCalibration(kitti::calibrationDirOf(drive));
    const std::vector<kitti::Frame> frames = kitti::listFrames(drive);
    ASSERT_FALSE(frames.empty());
    ASSERT_EQ(frames.front().name, "0000000000");
    data_ = kitti::loadFrame(frames.front(), calibration_.camera);
  }
  kitti::Calibration calibration_;
  kitti::FrameData data_;
};

TEST_F(KittiFrame0, ProjectedPointsFallInTheLowerPartOfTheImage) {
  const StereoCamera& camera = calibration_.camera;
  const SparseDisparity s =
      projectCloud(data_.cloud, calibration_.T_cam_velo, camera, ProjectionParams());
  const int projected = cv::countNonZero(s.disparity);
  int top_row = camera.height, below_centre = 0;
  double max_disparity = 0.0;
  for (int y = 0; y < s.disparity.rows; ++y) {
    for (int x = 0; x < s.disparity.cols; ++x) {
      const float d = s.disparity(y, x);
      if (d <= 0.f) continue;
      top_row = std::min(top_row, y);
      if (y > camera.cy) ++below_centre;
      max_disparity = std::max(max_disparity, static_cast<double>(d));
      EXPECT_GE(s.ring(y, x), 0);
    }
  }
  std::printf(
      "[ KITTI 0 ] in front %d, in image %d, pixels %d, top row %d, below cy %.1f %%, "
      "max d %.1f px\n",
      s.points_in_front, s.points_in_image, projected, top_row, 100.0 * below_centre / projected,
      max_disparity);
  EXPECT_GT(s.points_in_image, 15000);
  EXPECT_GT(projected, 0.9 * s.points_in_image);  // few collisions on the z-buffer
  // The HDL-64E looks at most ~2 deg above the horizon: nothing in the top quarter, and most
  // points below the principal point (84 % on this frame; top row 115 of 375).
  EXPECT_GT(top_row, camera.height / 4);
  EXPECT_GT(below_centre, 0.75 * projected);
  EXPECT_LT(max_disparity, 192.0);
}

TEST_F(KittiFrame0, BIStarCoversTheBandBetweenTopAndBottomLinesAndRemovesLeaks) {
  const StereoCamera& camera = calibration_.camera;
  const SparseDisparity s =
      projectCloud(data_.cloud, calibration_.T_cam_velo, camera, ProjectionParams());
  int removed = 0;
  ScanLines lines;
  const cv::Mat1f dense = upsampleBI(s, data_.left, BIParams(), &removed, &lines);
  const double coverage = coverageBetweenLines(lines.disparity, dense);
  std::printf(
      "[ KITTI 0 ] BI*: scan-line pixels %d, removed by Algorithm 1 %d, coverage between "
      "lines %.2f %%, dense pixels %d\n",
      cv::countNonZero(lines.disparity), removed, 100.0 * coverage, cv::countNonZero(dense));
  EXPECT_GT(removed, 0);
  EXPECT_GT(coverage, 0.90);

  const cv::Mat1f bf = upsampleBF(s, BFParams());
  std::printf("[ KITTI 0 ] BF*: coverage between lines %.2f %%, dense pixels %d\n",
              100.0 * coverageBetweenLines(lines.disparity, bf), cv::countNonZero(bf));
  EXPECT_GT(coverageBetweenLines(lines.disparity, bf), 0.5);
}

}  // namespace
}  // namespace lidar_stereo_fusion
