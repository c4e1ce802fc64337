// The stereo check of a LiDAR-made reference: exact removals on a hand-made disparity map, and
// SGBM finding a known fronto-parallel disparity on a synthetic textured pair.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "eval_test_scenes.h"
#include "lidar_stereo_fusion/eval/stereo_check.h"

namespace lidar_stereo_fusion {
namespace {

using test::camera;

TEST(StereoCheck, KeepsAgreeingPixelsAndRemovesTheRestByReason) {
  cv::Mat1f depth(2, 4, 0.f), stereo(2, 4, 0.f);
  // reference 10 m = 5 px everywhere but one empty pixel
  depth.setTo(10.f);
  depth(1, 3) = 0.f;
  stereo(0, 0) = 5.f;   // agrees exactly
  stereo(0, 1) = 7.9f;  // 2.9 px off: kept at 3 px
  stereo(0, 2) = 8.1f;  // 3.1 px off: removed
  stereo(0, 3) = 2.0f;  // 3 px off the other way: kept (the limit is inclusive)
  stereo(1, 0) = 0.f;   // no stereo: removed
  stereo(1, 1) = 5.5f;
  stereo(1, 2) = 9.f;  // removed
  stereo(1, 3) = 5.f;  // no reference: not looked at
  const StereoCheckCounts counts = removeStereoOutliers(depth, stereo, camera(4, 2), 3.0);
  EXPECT_EQ(counts.checked, 7);
  EXPECT_EQ(counts.removed_no_stereo, 1);
  EXPECT_EQ(counts.removed_disagreeing, 2);
  const cv::Mat1f expected = (cv::Mat1f(2, 4) << 10, 10, 0, 10, 0, 10, 0, 0);
  EXPECT_EQ(cv::countNonZero(depth != expected), 0) << depth;
}

TEST(StereoCheck, RefusesWrongSizesAndTolerances) {
  cv::Mat1f depth(2, 4, 10.f), stereo(2, 3, 5.f);
  EXPECT_THROW(removeStereoOutliers(depth, stereo, camera(4, 2), 3.0), std::invalid_argument);
  stereo = cv::Mat1f(2, 4, 5.f);
  for (const double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(removeStereoOutliers(depth, stereo, camera(4, 2), bad), std::invalid_argument);
  }
  EXPECT_EQ(cv::countNonZero(depth != 10.f), 0);  // nothing changed by a refused call
}

TEST(StereoCheck, SgbmFindsTheDisparityOfATexturedPlane) {
  // a fronto-parallel plane at 20 px, random texture (SGBM needs one)
  cv::Mat1b left, right;
  test::shiftedTexture(300, 120, 20, left, right);
  cv::Mat bgr_left, bgr_right;
  cv::cvtColor(left, bgr_left, cv::COLOR_GRAY2BGR);
  cv::cvtColor(right, bgr_right, cv::COLOR_GRAY2BGR);
  const cv::Mat1f d = sgbmDisparity(bgr_left, bgr_right);
  ASSERT_EQ(d.size(), left.size());
  int near_truth = 0, valid = 0;
  for (int y = 10; y < 110; ++y) {
    for (int x = 150; x < 290; ++x) {  // right of SGBM's 128-disparity margin
      if (d(y, x) <= 0.f) continue;
      ++valid;
      if (std::abs(d(y, x) - 20.f) <= 0.25f) ++near_truth;
    }
  }
  EXPECT_GT(valid, 100 * 140 * 9 / 10);
  EXPECT_GT(near_truth, valid * 99 / 100);
  EXPECT_EQ(cv::countNonZero(d < 0.f), 0);  // none is negative: "none" is 0
}

}  // namespace
}  // namespace lidar_stereo_fusion
