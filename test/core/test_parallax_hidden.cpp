// Stage 2, BI* step 2b: scan-line pixels the camera cannot see past a nearer line, by the
// LiDAR-camera offset (removeParallaxHidden). Exact answers on hand-made columns: camera fx = fy =
// 100 px, cx = cy = 50 px, baseline 0.5 m (z = 50 / d). With the LiDAR origin o = (0, oy, 0), the
// LiDAR's ray to a pixel p at row v_p lands, at the depth of a line q, on row v_p + 100 oy (1 / z_q
// - 1 / z_p) = v_p + 2 oy (d_q - d_p): with oy = -0.1 (10 cm above the camera) 0.2 (d_q - d_p) rows
// above p.
#include <limits>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/upsampling.h"
#include "test_scenes.h"
#include "upsampling_test_util.h"

namespace lidar_stereo_fusion {
namespace {

using namespace test;  // NOLINT: the maps of upsampling_test_util.h

StereoCamera camera100() { return centredCamera(100, 100, 100.0); }

/// Writes a scan-line pixel.
void put(ScanLines& l, int x, int y, float d, short ring) {
  l.disparity(y, x) = d;
  l.ring(y, x) = ring;
}

const Eigen::Vector3d kAbove(0.0, -0.1, 0.0);  // the LiDAR 10 cm above the camera

TEST(RemoveParallaxHidden, ClearsBackgroundAboveANearerLineWithinTheShiftOfItsRay) {
  ScanLines l = emptyLines(100, 100);
  // d 5 over d 25: the ray to the background pixel lands 0.2 * 20 = 4 rows above it.
  put(l, 10, 40, 5.f, 0);  // 3 rows above the foreground: hidden more likely than not
  put(l, 10, 43, 25.f, 1);
  put(l, 20, 40, 5.f, 0);  // 5 rows above it: more likely seen
  put(l, 20, 45, 25.f, 1);
  put(l, 30, 40, 5.f, 0);  // the line below nearer by 1.5 px only (max_disp_diff): not an edge
  put(l, 30, 41, 6.5f, 1);
  std::vector<cv::Point> removed;
  EXPECT_EQ(removeParallaxHidden(l, camera100(), kAbove, BIParams(), &removed), 1);
  ASSERT_EQ(removed.size(), 1u);
  EXPECT_EQ(removed[0], cv::Point(10, 40));
  EXPECT_EQ(l.disparity(40, 10), 0.f);
  EXPECT_EQ(l.ring(40, 10), -1);
  EXPECT_EQ(l.disparity(43, 10), 25.f);  // the foreground stays
  EXPECT_EQ(l.disparity(40, 20), 5.f);
  EXPECT_EQ(l.disparity(40, 30), 5.f);
  EXPECT_EQ(cv::countNonZero(l.disparity), 5);
}

TEST(RemoveParallaxHidden, TheSideFollowsTheLidarAndItsDepthOffsetCounts) {
  // Below the camera the LiDAR sees under bottom edges: the background below a nearer line
  // (its ray lands 4 rows below it) goes, the one above stays.
  ScanLines below = emptyLines(100, 100);
  put(below, 10, 57, 25.f, 1);
  put(below, 10, 60, 5.f, 0);
  put(below, 20, 40, 5.f, 0);
  put(below, 20, 43, 25.f, 1);
  std::vector<cv::Point> removed;
  removeParallaxHidden(below, camera100(), Eigen::Vector3d(0.0, 0.1, 0.0), BIParams(), &removed);
  EXPECT_EQ(removed, std::vector<cv::Point>{cv::Point(10, 60)});
  // 50 cm behind the camera as well, the ray lands farther from p: (z_p 10 m, z_q 2 m, p at row
  // 40) 50 + 100 (-0.1 + 2.5 / 10.5 (-1 + 0.1)) / 2 = 34.29, 5.71 rows above p, so a foreground
  // 5 rows below hides it (without the offset: 4 rows, it would stay).
  ScanLines behind = emptyLines(100, 100);
  put(behind, 10, 40, 5.f, 0);
  put(behind, 10, 45, 25.f, 1);
  ScanLines same = behind;
  same.disparity = behind.disparity.clone();
  same.ring = behind.ring.clone();
  EXPECT_EQ(removeParallaxHidden(behind, camera100(), Eigen::Vector3d(0, -0.1, -0.5), BIParams()),
            1);
  EXPECT_EQ(removeParallaxHidden(same, camera100(), kAbove, BIParams()), 0);
}

TEST(RemoveParallaxHidden, DecidesOnTheInputStateAndOrdersByColumnThenRow) {
  ScanLines l = emptyLines(100, 100);
  // Column 10: p1 (row 38, d 5) over p2 (row 40, d 5.5) over the foreground (row 42, d 30). p2
  // goes (4.9 rows >= 2); p1's neighbour below is p2, not nearer: it stays, though after p2's
  // removal the foreground (5 rows of shift, 4 rows away) would hide it.
  put(l, 10, 38, 5.f, 0);
  put(l, 10, 40, 5.5f, 1);
  put(l, 10, 42, 30.f, 2);
  put(l, 5, 70, 5.f, 0);  // an earlier column, lower in the image
  put(l, 5, 72, 30.f, 1);
  std::vector<cv::Point> removed;
  removeParallaxHidden(l, camera100(), kAbove, BIParams(), &removed);
  EXPECT_EQ(removed, (std::vector<cv::Point>{cv::Point(5, 70), cv::Point(10, 40)}));
  EXPECT_EQ(l.disparity(38, 10), 5.f);
}

TEST(RemoveParallaxHidden, NothingWithoutAnOffsetOrWhenSwitchedOff) {
  ScanLines l = emptyLines(100, 100);
  put(l, 10, 40, 5.f, 0);
  put(l, 10, 41, 25.f, 1);
  EXPECT_EQ(removeParallaxHidden(l, camera100(), Eigen::Vector3d::Zero(), BIParams()), 0);
  BIParams off;
  off.remove_parallax_hidden = false;
  EXPECT_EQ(removeParallaxHidden(l, camera100(), kAbove, off), 0);
  EXPECT_EQ(removeParallaxHidden(l, camera100(), kAbove, BIParams()), 1);
}

TEST(RemoveParallaxHidden, RejectsAnInvalidCameraOrOrigin) {
  ScanLines l = emptyLines(100, 100);
  put(l, 10, 40, 5.f, 0);
  StereoCamera bad = camera100();
  bad.baseline = 0.0;
  EXPECT_THROW(removeParallaxHidden(l, bad, kAbove, BIParams()), std::invalid_argument);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(removeParallaxHidden(l, camera100(), Eigen::Vector3d(0, nan, 0), BIParams()),
               std::invalid_argument);
}

}  // namespace
}  // namespace lidar_stereo_fusion
