// Mixed edge pixels to the nearer surface (core/mixed_edges.h) on small maps with exact answers: a
// boundary pixel whose colour lies at least min_fraction of the way to the nearer neighbour's
// takes its disparity; one that does not, a step below the edge ratio, a far side that is not
// p's surface, too little contrast, a LiDAR point the output agrees with and the border stay; the
// decisions are taken on the input; grey images count 3 |a - b|; bad input is refused.
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidar_stereo_fusion/core/mixed_edges.h"
#include "lidar_stereo_fusion/core/pipeline.h"

namespace lidar_stereo_fusion {
namespace {

constexpr float kNear = 20.f, kFar = 10.f;  // disparities [px]: a depth ratio of 2
constexpr int kEdge = 4;                    // columns < kEdge hold the near surface

/// A 9 x 9 scene: the near surface (dark, 0) left of column kEdge, the far one (bright, 200) from
/// it on, in both maps; column kEdge's colour is `boundary` (the far surface's disparity).
struct Scene {
  cv::Mat1f disparity = cv::Mat1f(9, 9, kFar);
  cv::Mat3b image = cv::Mat3b(9, 9, cv::Vec3b(200, 200, 200));
  explicit Scene(uchar boundary) {
    disparity.colRange(0, kEdge).setTo(kNear);
    image.colRange(0, kEdge).setTo(cv::Vec3b(0, 0, 0));
    image.col(kEdge).setTo(cv::Vec3b(boundary, boundary, boundary));
  }
  int run(const MixedEdgeParams& params = {}, const cv::Mat1f& sparse = {},
          const cv::Mat1f& lines = {}) {
    return nearerAtMixedEdges(disparity, image, sparse, lines, 0.5f, params);
  }
};

TEST(MixedEdges, ABoundaryPixelMostlyOfTheNearerColourTakesItsDisparity) {
  // 40 lies 0.8 of the way from 200 to 0 (>= 0.75): the inner rows of the column go near.
  Scene s(40);
  EXPECT_EQ(s.run(), 7);
  for (int y = 1; y < 8; ++y) EXPECT_EQ(s.disparity(y, kEdge), kNear) << y;
  EXPECT_EQ(s.disparity(0, kEdge), kFar);  // the border stays
  EXPECT_EQ(s.disparity(8, kEdge), kFar);
  EXPECT_EQ(cv::countNonZero(s.disparity == kNear), 9 * kEdge + 7);
}

TEST(MixedEdges, ABoundaryPixelOfHalfAndHalfStays) {
  Scene s(100);  // 0.5 of the way
  EXPECT_EQ(s.run(), 0);
  MixedEdgeParams half;
  half.min_fraction = 0.5f;  // at the threshold: taken
  EXPECT_EQ(s.run(half), 7);
}

TEST(MixedEdges, ASmallStepOrAFarSideOfAnotherSurfaceStays) {
  Scene slope(40);
  slope.disparity.colRange(kEdge, 9).setTo(kNear / 1.29f);  // below the ratio 1.3
  EXPECT_EQ(slope.run(), 0);
  Scene other(40);
  other.disparity.col(kEdge + 1).setTo(1.2f * kFar);  // p' not on p's surface (> 1.1 d)
  EXPECT_EQ(other.run(), 0);
  Scene empty_far(40);
  empty_far.disparity.col(kEdge + 1).setTo(0.f);  // no p'
  EXPECT_EQ(empty_far.run(), 0);
}

TEST(MixedEdges, TooLittleContrastStays) {
  Scene s(40);
  s.image.colRange(0, kEdge).setTo(cv::Vec3b(185, 185, 185));  // L1 contrast 45
  s.image.col(kEdge).setTo(cv::Vec3b(188, 188, 188));          // 0.8 of the way
  EXPECT_EQ(s.run(), 0);
  MixedEdgeParams low;
  low.min_contrast = 45.f;
  EXPECT_EQ(s.run(low), 7);
}

TEST(MixedEdges, ALidarPointTheOutputAgreesWithStays) {
  Scene s(40);
  cv::Mat1f sparse(9, 9, 0.f);
  sparse(3, kEdge) = kFar + 0.4f;  // within the tolerance 0.5: stays
  sparse(5, kEdge) = kFar + 2.f;   // the output disagrees: no measurement of this output
  cv::Mat1f lines = sparse.clone();
  lines(6, kEdge) = 0.f;
  sparse(6, kEdge) = kFar;  // removed from the scan lines (occluded): no measurement
  EXPECT_EQ(s.run({}, sparse, lines), 6);
  EXPECT_EQ(s.disparity(3, kEdge), kFar);
  EXPECT_EQ(s.disparity(5, kEdge), kNear);
  EXPECT_EQ(s.disparity(6, kEdge), kNear);
}

TEST(MixedEdges, DecidesOnTheInput) {
  // Column kEdge (10) lies 0.82 of the way from its far side (56) to the near surface (0); column
  // kEdge + 1 (56) would lie 0.76 of the way from 200 to column kEdge once that is near. Decided
  // on the input, where column kEdge is still far, it stays.
  Scene s(10);
  s.image.col(kEdge + 1).setTo(cv::Vec3b(56, 56, 56));
  EXPECT_EQ(s.run(), 7);
  for (int y = 1; y < 8; ++y) {
    EXPECT_EQ(s.disparity(y, kEdge), kNear) << y;
    EXPECT_EQ(s.disparity(y, kEdge + 1), kFar) << y;
  }
  EXPECT_EQ(s.run(), 7);  // a second pass takes the next column: the step is not idempotent
}

TEST(MixedEdges, EveryDirection) {
  // The near surface left, right, above (a bottom edge) and below (a top edge) of the boundary.
  for (int turn = 0; turn < 4; ++turn) {
    Scene s(40);
    if (turn == 1) {
      cv::flip(s.disparity, s.disparity, 1);
      cv::flip(s.image, s.image, 1);
    } else if (turn >= 2) {
      cv::transpose(s.disparity, s.disparity);
      cv::transpose(s.image, s.image);
      if (turn == 3) {
        cv::flip(s.disparity, s.disparity, 0);
        cv::flip(s.image, s.image, 0);
      }
    }
    EXPECT_EQ(s.run(), 7) << turn;
    EXPECT_EQ(cv::countNonZero(s.disparity == kNear), 9 * kEdge + 7) << turn;
  }
}

TEST(MixedEdges, TheSameForAnyThreadCount) {
  // Random blocks of two depths and random colours: many candidates in every strip of rows.
  cv::RNG rng(7);
  cv::Mat1f disparity(61, 47);
  cv::Mat3b image(61, 47);
  for (int y = 0; y < disparity.rows; ++y) {
    for (int x = 0; x < disparity.cols; ++x) {
      disparity(y, x) = ((x / 3 + y / 4) % 2) ? kNear : kFar;
      image(y, x) = cv::Vec3b(rng.uniform(0, 256), rng.uniform(0, 256), rng.uniform(0, 256));
    }
  }
  cv::Mat1f one = disparity.clone();
  const int changed = nearerAtMixedEdges(one, image, {}, {}, 0.5f, {}, 1);
  EXPECT_GT(changed, 20);
  for (int threads : {2, 3, 8}) {
    cv::Mat1f many = disparity.clone();
    EXPECT_EQ(nearerAtMixedEdges(many, image, {}, {}, 0.5f, {}, threads), changed) << threads;
    EXPECT_EQ(cv::countNonZero(many != one), 0) << threads;
  }
}

TEST(MixedEdges, GreyImagesCountThreeTimesTheDifference) {
  Scene colour(40);
  cv::Mat1b grey;
  cv::cvtColor(colour.image, grey, cv::COLOR_BGR2GRAY);
  cv::Mat1f d = colour.disparity.clone();
  EXPECT_EQ(nearerAtMixedEdges(d, grey, {}, {}, 0.5f, {}), colour.run());
  EXPECT_EQ(cv::countNonZero(d != colour.disparity), 0);
}

TEST(MixedEdges, RefusesBadInput) {
  Scene s(40);
  const cv::Mat1f small(3, 3, 1.f);
  EXPECT_THROW(nearerAtMixedEdges(s.disparity, cv::Mat3b(3, 3), {}, {}, 0.5f, {}),
               std::invalid_argument);
  EXPECT_THROW(nearerAtMixedEdges(s.disparity, cv::Mat1f(9, 9), {}, {}, 0.5f, {}),
               std::invalid_argument);
  EXPECT_THROW(nearerAtMixedEdges(s.disparity, s.image, small, small, 0.5f, {}),
               std::invalid_argument);
  EXPECT_THROW(nearerAtMixedEdges(s.disparity, s.image, cv::Mat1f(9, 9), {}, 0.5f, {}),
               std::invalid_argument);
  MixedEdgeParams bad;
  bad.min_fraction = 1.5f;
  EXPECT_THROW(s.run(bad), std::invalid_argument);
  bad = {};
  bad.min_contrast = -1.f;
  EXPECT_THROW(s.run(bad), std::invalid_argument);
  EXPECT_THROW(nearerAtMixedEdges(s.disparity, s.image, {}, {}, -1.f, {}), std::invalid_argument);
  FusionParams params;
  params.patchmatch.mixed_edge_fraction = 1.5;
  EXPECT_THROW(params.validate(), std::invalid_argument);
  params.patchmatch.mixed_edge_fraction = 0.0;  // off
  EXPECT_NO_THROW(params.validate());
}

}  // namespace
}  // namespace lidar_stereo_fusion
