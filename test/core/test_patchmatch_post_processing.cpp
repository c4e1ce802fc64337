// PatchMatch after the search, with exact answers: the left-right check and filling
// (post_processing.h). The coarse start (coarse_to_fine.h): test_patchmatch_levels.cpp.
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/patchmatch/post_processing.h"
#include "patchmatch_steps_util.h"

namespace lsf = lidar_stereo_fusion;
namespace pm = lidar_stereo_fusion::patchmatch;

using namespace lidar_stereo_fusion::test;  // NOLINT: the views of patchmatch_steps_util.h

TEST(PatchMatchPostProcessing, LeftRightCheckMarksDisagreementsAndKeepsWhatItCannotCheck) {
  cv::Mat1f left(1, 8, 2.f), right(1, 8, 2.f);
  right(0, 3) = 5.f;  // left pixel 5 (d = 2) matches right pixel 3: disagrees by 3
  const cv::Mat1b bad = pm::leftRightCheck(left, right, 1.f, {});
  EXPECT_EQ(bad(0, 5), 255);
  EXPECT_EQ(bad(0, 4), 0);
  EXPECT_EQ(bad(0, 0), 0);  // match at -2: outside, kept
  EXPECT_EQ(pm::leftRightCheck(left, right, 1.f, {}, true)(0, 0), 255);  // ... unless asked
  std::vector<uint8_t> keep(8, 0);
  keep[5] = 1;
  EXPECT_EQ(pm::leftRightCheck(left, right, 1.f, keep)(0, 5), 0);  // locked: kept
}

TEST(PatchMatchPostProcessing, ConfidentPriorFillsElseTheBackgroundNeighbour) {
  lsf::PatchMatchParams p = params3x3();
  cv::Mat1f prior = cv::Mat1f::zeros(1, 7), conf = cv::Mat1f::zeros(1, 7);
  prior(0, 2) = 9.f;
  conf(0, 2) = 0.8f;
  prior(0, 4) = 7.f;
  conf(0, 4) = 0.2f;  // too weak to fill
  Views v = prepare({uniform(7, 1, 60), prior, {}, conf}, {uniform(7, 1, 60)}, p);
  for (int x = 0; x < 7; ++x) v.left.planes[x] = pm::Plane{0.f, 0.f, x < 4 ? 12.f : 3.f};
  cv::Mat1f disparity = pm::disparityOf(v.left);
  cv::Mat1b bad = cv::Mat1b::zeros(1, 7);
  bad(0, 2) = bad(0, 4) = 255;
  pm::fillHoles(v.left, bad, {1, 10.f, 0.5f, 192.f, p.simd_path}, disparity, 1);
  EXPECT_EQ(disparity(0, 2), 9.f);  // the prior
  EXPECT_EQ(disparity(0, 4), 3.f);  // min(12 from the left, 3 from the right): the background
  EXPECT_EQ(disparity(0, 0), 12.f);
}

TEST(PatchMatchPostProcessing, AFillNeverPassesTheSearchRange) {
  lsf::PatchMatchParams p = params3x3();
  Views v = prepare({uniform(9, 1, 60)}, {uniform(9, 1, 60)}, p);
  // d = 20 x + 80 on pixels 0..4 (160 px at x = 4); pixels 5..8 failed the check and have no
  // right neighbour: pixel 4's plane reaches 180, 200, 220, 240 px there, beyond 192 from x = 6.
  for (int x = 0; x < 9; ++x) v.left.planes[x] = pm::Plane{20.f, 0.f, 80.f};
  cv::Mat1f disparity = pm::disparityOf(v.left);
  cv::Mat1b bad = cv::Mat1b::zeros(1, 9);
  for (int x = 5; x < 9; ++x) bad(0, x) = 255;
  pm::fillHoles(v.left, bad, {2, 10.f, 0.5f, 192.f, p.simd_path}, disparity, 1);
  for (int x = 5; x < 9; ++x) EXPECT_LE(disparity(0, x), 192.f) << x;
  EXPECT_EQ(disparity(0, 8), 0.f);    // its window (pixels 6, 8) holds no fill: left empty
  EXPECT_EQ(disparity(0, 5), 140.f);  // the median of its window: pixels 3 (140) and 5 (180)
}
