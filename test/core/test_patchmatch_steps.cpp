// PatchMatch, step by step, with exact answers: the plane xi (patchmatch/plane.h), the cost C with
// w and phi (cost.h), the search steps (propagation.h) and view propagation. The left-right check,
// filling and the coarse start: test_patchmatch_levels.cpp.
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/patchmatch/cost.h"
#include "lidar_stereo_fusion/core/patchmatch/propagation.h"
#include "patchmatch_steps_util.h"
#include "test_scenes.h"

namespace lsf = lidar_stereo_fusion;
namespace pm = lidar_stereo_fusion::patchmatch;

using lidar_stereo_fusion::test::costOf;
using lidar_stereo_fusion::test::frontoParallelAround;
using lidar_stereo_fusion::test::params3x3;
using lidar_stereo_fusion::test::prepare;
using lidar_stereo_fusion::test::propagationOnly;
using lidar_stereo_fusion::test::uniform;
using lidar_stereo_fusion::test::Views;

TEST(PatchMatchPlane, NormalFormAndTransferBetweenViewsAreExact) {
  const pm::Plane p = pm::planeFromNormal(10.f, 20.f, 8.f, 0.f, 0.f, 1.f);
  EXPECT_EQ(p.a, 0.f);
  EXPECT_EQ(p.b, 0.f);
  EXPECT_EQ(p.c, 8.f);
  // d = 0.25 x + 2: left point (8, y, 4) is the right point (4, y, 4).
  const pm::Plane left{0.25f, 0.f, 2.f};
  const pm::Plane right = pm::transferPlane(left, true);
  EXPECT_FLOAT_EQ(right.at(4.f, 0.f), 4.f);
  const pm::Plane back = pm::transferPlane(right, false);
  EXPECT_FLOAT_EQ(back.a, left.a);
  EXPECT_FLOAT_EQ(back.c, left.c);
  float nx, ny, nz;
  pm::normalOf(left, nx, ny, nz);
  const pm::Plane again = pm::planeFromNormal(8.f, 3.f, left.at(8.f, 3.f), nx, ny, nz);
  EXPECT_FLOAT_EQ(again.a, left.a);
  EXPECT_FLOAT_EQ(again.c, left.c);
}

TEST(PatchMatchCost, SupportWeightIsExpOfMinusColourDistanceOverDelta) {
  const lsf::PatchMatchParams p = params3x3();
  const Views v = prepare({uniform(8, 8, 100)}, {uniform(8, 8, 100)}, p);
  const pm::MatchingCost cost(p, v.left, v.right);
  EXPECT_EQ(cost.supportWeight(0.f), 1.f);
  EXPECT_FLOAT_EQ(cost.supportWeight(10.f), std::exp(-1.f));  // delta = 10
  EXPECT_FLOAT_EQ(cost.supportWeight(25.f), std::exp(-2.5f));
}

TEST(PatchMatchCost, WithoutLidarThePhiIsTheRenormalisedImageTerm) {
  // The right image is 4 grey levels brighter: |I_p' - I_q|_1 = 12 > lambda_col = 10, gradients 0.
  const lsf::PatchMatchParams p = params3x3();
  const Views v = prepare({uniform(12, 9, 100)}, {uniform(12, 9, 104)}, p);
  const pm::MatchingCost cost(p, v.left, v.right);
  // 9 samples, w = 1, phi = (alpha min(12, 10) + beta 0) / (alpha + beta) = 1.
  EXPECT_FLOAT_EQ(costOf(cost, 6, 4, pm::Plane{0.f, 0.f, 2.f}), 9.f * 0.01f * 10.f / 0.1f);
}

TEST(PatchMatchCost, ConfidenceWeightsTheLidarTermAndTheImageTermTakesTheRest) {
  lsf::PatchMatchParams p = params3x3();
  cv::Mat1f prior(9, 12, 5.f), conf(9, 12, 0.5f);
  const Views v = prepare({uniform(12, 9, 100), prior, {}, conf}, {uniform(12, 9, 104)}, p);
  const pm::MatchingCost cost(p, v.left, v.right);
  // kappa = 0.9 * 0.5 = 0.45: phi = 0.55 / (alpha + beta) * alpha min(12, 10) + 0.45 min(|5 - 6|,
  // 2) = 0.55 + 0.45 = 1 per sample (every match of pixel 9's window lies inside the right image).
  EXPECT_FLOAT_EQ(costOf(cost, 9, 4, pm::Plane{0.f, 0.f, 6.f}), 9.f);
  // A match outside the other image costs the truncations: alpha 10 + beta 2 = 0.28 before the
  // factor 5.5, so pixel 6's left column (matches at x = -1) costs 1.54 + 0.45 per sample.
  EXPECT_FLOAT_EQ(costOf(cost, 6, 4, pm::Plane{0.f, 0.f, 6.f}), 6.f + 3.f * (1.54f + 0.45f));
  // The paper's reading: phi = alpha * 10 + gamma min(|5 - 6|, 2) regardless of confidence.
  p.confidence_weighting = false;
  p.alpha = 0.1;
  p.beta = 0.0;
  const Views paper = prepare({uniform(12, 9, 100), prior, {}, conf}, {uniform(12, 9, 104)}, p);
  const pm::MatchingCost paper_cost(p, paper.left, paper.right);
  EXPECT_FLOAT_EQ(costOf(paper_cost, 9, 4, pm::Plane{0.f, 0.f, 6.f}), 9.f * (1.f + 0.9f));
}

TEST(PatchMatchCost, TheRoundWindowSumsTheSamplesWithinTheRadius) {
  // params3x3's images with a round 3x3 window: the centre and its 4 neighbours (the corners lie
  // sqrt(2) px away), each costing 1 as in the square's test above.
  lsf::PatchMatchParams p = params3x3();
  p.window_round = true;
  const Views v = prepare({uniform(12, 9, 100)}, {uniform(12, 9, 104)}, p);
  const pm::MatchingCost cost(p, v.left, v.right);
  EXPECT_EQ(cost.rows().count, 5);
  EXPECT_FLOAT_EQ(costOf(cost, 6, 4, pm::Plane{0.f, 0.f, 2.f}), 5.f);
  // On the top row the sample above is outside the image: 4 samples.
  EXPECT_FLOAT_EQ(costOf(cost, 6, 0, pm::Plane{0.f, 0.f, 2.f}), 4.f);
  // The square: 9 and, on the top row, 6.
  p.window_round = false;
  const pm::MatchingCost square(p, v.left, v.right);
  EXPECT_FLOAT_EQ(costOf(square, 6, 4, pm::Plane{0.f, 0.f, 2.f}), 9.f);
  EXPECT_FLOAT_EQ(costOf(square, 6, 0, pm::Plane{0.f, 0.f, 2.f}), 6.f);
}

TEST(PatchMatchCost, PaperReadingChargesTheTruncationWhereThePriorIsEmpty) {
  lsf::PatchMatchParams p = params3x3();
  p.confidence_weighting = false;
  cv::Mat1f prior = cv::Mat1f::zeros(9, 12);
  prior(4, 6) = 3.f;  // only the centre has a prior
  const Views v = prepare({uniform(12, 9, 100), prior}, {uniform(12, 9, 100)}, p);
  const pm::MatchingCost cost(p, v.left, v.right);
  // Image term 0; centre: gamma |3 - 3| = 0; the 8 others: gamma lambda_disp = 1.8 each.
  EXPECT_FLOAT_EQ(costOf(cost, 6, 4, pm::Plane{0.f, 0.f, 3.f}), 8.f * 0.9f * 2.f);
}

TEST(PatchMatchCost, TheTruePlaneOfATexturedPairCostsNothingAndEarlyExitKeepsTheOrder) {
  const lsf::test::PlaneScene s = lsf::test::PlaneScene::make(60, 30, 0.0, 0.0, 7.0, 3);
  lsf::PatchMatchParams p = params3x3();
  p.window_radius = 2;
  const Views v = prepare({s.left}, {s.right}, p);
  const pm::MatchingCost cost(p, v.left, v.right);
  EXPECT_NEAR(costOf(cost, 30, 15, pm::Plane{0.f, 0.f, 7.f}), 0.f, 1e-3f);
  const float wrong = costOf(cost, 30, 15, pm::Plane{0.f, 0.f, 11.f});
  EXPECT_GT(wrong, 1.f);
  pm::WindowCache cache;
  cost.buildWindow(30, 15, cache);
  EXPECT_GE(cost.aggregate(cache, pm::Plane{0.f, 0.f, 11.f}, 0.5f), 0.5f);  // stopped early
}

TEST(PatchMatchSearch, BoundsRestrictTheAdmissibleDisparities) {
  lsf::PatchMatchParams p = params3x3();
  lsf::ScanLineBounds b;
  b.lo = cv::Mat1f(5, 8, 4.f);
  b.hi = cv::Mat1f(5, 8, 6.f);
  b.range = cv::Mat1f(5, 8, 2.f);
  Views v = prepare({uniform(8, 5, 50), cv::Mat1f(5, 8, 5.f), b}, {uniform(8, 5, 50)}, p);
  const pm::PlaneSearch search(p, v.left, v.right);
  EXPECT_TRUE(search.admissible(3, 2, 4.f));
  EXPECT_TRUE(search.admissible(3, 2, 6.f));
  EXPECT_FALSE(search.admissible(3, 2, 3.99f));
  EXPECT_FALSE(search.admissible(3, 2, 6.01f));
  EXPECT_FALSE(search.admissible(3, 2, 0.5f));  // below min_disparity regardless
}

TEST(PatchMatchSearch, LockedPixelsKeepThePriorPlaneWithOneSidedSlopes) {
  // A prior with slope 0.5 px per row on rows 1..3 (row 0 and 4 empty), confidence 1: locked.
  cv::Mat1f prior = cv::Mat1f::zeros(5, 6), conf = cv::Mat1f::zeros(5, 6);
  for (int y = 1; y <= 3; ++y) {
    for (int x = 0; x < 6; ++x) {
      prior(y, x) = 10.f + 0.5f * y;
      conf(y, x) = 1.f;
    }
  }
  lsf::PatchMatchParams p = params3x3();
  Views v = prepare({uniform(6, 5, 80), prior, {}, conf}, {uniform(6, 5, 80)}, p);
  ASSERT_TRUE(v.left.isLocked(3 * 6 + 2));
  ASSERT_FALSE(v.left.isLocked(4 * 6 + 2));
  const pm::Plane bottom = pm::priorPlane(v.left, 2, 3);  // no value below: one-sided slope
  EXPECT_FLOAT_EQ(bottom.b, 0.5f);
  EXPECT_FLOAT_EQ(bottom.at(2.f, 4.f), 12.f);  // extrapolates the surface one row down
  const pm::PlaneSearch search(p, v.left, v.right);
  pm::Rng rng(1);
  const pm::Plane init = search.initialPlane(2, 3, rng);
  EXPECT_FLOAT_EQ(init.at(2.f, 3.f), 11.5f);
  v.left.planes[3 * 6 + 2] = pm::Plane{0.f, 0.f, 99.f};
  pm::WindowCache cache;
  search.processPixel(2, 3, true, 0, cache);  // a locked pixel is not searched
  EXPECT_EQ(v.left.planes[3 * 6 + 2].c, 99.f);
}

TEST(PatchMatchSearch, RefinementFindsTheTruePlaneAndStaysInsideTheBounds) {
  const lsf::test::PlaneScene s = lsf::test::PlaneScene::make(80, 30, 0.0, 0.0, 9.0, 5);
  lsf::PatchMatchParams p = params3x3();
  p.window_radius = 3;
  lsf::ScanLineBounds b;
  b.lo = cv::Mat1f(30, 80, 6.f);
  b.hi = cv::Mat1f(30, 80, 12.f);
  b.range = cv::Mat1f(30, 80, 6.f);
  Views v = prepare({s.left, cv::Mat1f(), b}, {s.right}, p);
  const pm::PlaneSearch search(p, v.left, v.right);
  pm::WindowCache cache;
  search.cost().buildWindow(40, 15, cache);
  pm::Plane best{0.f, 0.f, 7.f};
  float best_cost = search.cost().aggregate(cache, best, std::numeric_limits<float>::max());
  for (int i = 0; i < 20; ++i) {
    pm::Rng rng(pm::streamKey(42, 0, i, 0));
    search.refine(40, 15, cache, rng, best, best_cost);
    ASSERT_GE(best.at(40.f, 15.f), 6.f);
    ASSERT_LE(best.at(40.f, 15.f), 12.f);
  }
  EXPECT_NEAR(best.at(40.f, 15.f), 9.f, 0.25f);
}

TEST(PatchMatchCost, WindowOffsetsAreEveryStrideOrDyadic) {
  EXPECT_EQ(pm::windowOffsets(8, 2, false), (std::vector<int>{-8, -6, -4, -2, 0, 2, 4, 6, 8}));
  EXPECT_EQ(pm::windowOffsets(8, 2, true), (std::vector<int>{-8, -4, -2, 0, 2, 4, 8}));
  EXPECT_EQ(pm::windowOffsets(4, 1, true), (std::vector<int>{-4, -2, -1, 0, 1, 2, 4}));
  EXPECT_EQ(pm::windowOffsets(6, 2, true), (std::vector<int>{-4, -2, 0, 2, 4}));
  EXPECT_EQ(pm::windowOffsets(5, 5, true), pm::windowOffsets(5, 5, false));  // {-5, 0, 5}
}

TEST(PatchMatchCost, WindowRowsAreTheSquareOrTheDiscWithinTheRadius) {
  const std::vector<int> dyadic = pm::windowOffsets(8, 2, true);  // -8 -4 -2 0 2 4 8
  const pm::WindowRows square = pm::windowRows(dyadic, 8, false);
  EXPECT_EQ(square.first, std::vector<int>(7, 0));
  EXPECT_EQ(square.end, std::vector<int>(7, 7));
  EXPECT_EQ(square.count, 49);
  // Round: rows +-8 hold dx = 0 alone; rows +-4 and +-2 hold |dx| <= 4 (4^2 + 8^2 > 64); row 0
  // all seven.
  const pm::WindowRows round = pm::windowRows(dyadic, 8, true);
  EXPECT_EQ(round.first, (std::vector<int>{3, 1, 1, 0, 1, 1, 3}));
  EXPECT_EQ(round.end, (std::vector<int>{4, 6, 6, 7, 6, 6, 4}));
  EXPECT_EQ(round.count, 29);
  // The levels of the coarse start: radius 4, stride 1 (-4 -2 -1 0 1 2 4) and radius 2, stride 1.
  EXPECT_EQ(pm::windowRows(pm::windowOffsets(4, 1, true), 4, true).count, 29);
  EXPECT_EQ(pm::windowRows(pm::windowOffsets(2, 1, true), 2, true).count, 13);
  // The paper's 3x3 samples of 11x11 (-5 0 5): the corners are 7.1 px away.
  EXPECT_EQ(pm::windowRows(pm::windowOffsets(5, 5, false), 5, true).count, 5);
  EXPECT_EQ(pm::windowRows(pm::windowOffsets(5, 5, false), 5, false).count, 9);
}

TEST(PatchMatchSearch, SubpixelStepMovesDToTheCostMinimum) {
  const lsf::test::PlaneScene s = lsf::test::PlaneScene::make(80, 30, 0.0, 0.0, 9.0, 5);
  lsf::PatchMatchParams p = params3x3();
  p.window_radius = 3;
  Views v = prepare({s.left}, {s.right}, p);
  const pm::PlaneSearch search(p, v.left, v.right);
  pm::WindowCache cache;
  search.cost().buildWindow(40, 15, cache);
  for (const float start : {8.96f, 9.05f}) {
    pm::Plane best{0.f, 0.f, start};
    float best_cost = search.cost().aggregate(cache, best, std::numeric_limits<float>::max());
    const float start_cost = best_cost;
    search.subpixelStep(40, 15, cache, best, best_cost);
    EXPECT_EQ(best_cost, pm::kUnknownCost) << start;  // the vertex is not evaluated ...
    EXPECT_LT(search.cost().aggregate(cache, best, std::numeric_limits<float>::max()), start_cost)
        << start;  // ... and costs less
    EXPECT_LT(std::abs(best.c - 9.f), 0.6f * std::abs(start - 9.f)) << start;
    EXPECT_EQ(best.a, 0.f);  // the normal is kept
    EXPECT_EQ(best.b, 0.f);
  }
}

TEST(PatchMatchSearch, WithoutRefinementAPixelOnlyTakesItsNeighboursPlane) {
  const lsf::test::PlaneScene s = lsf::test::PlaneScene::make(80, 30, 0.0, 0.0, 9.0, 5);
  lsf::PatchMatchParams p = params3x3();
  p.window_radius = 3;
  Views v = prepare({s.left}, {s.right}, p);
  for (const bool refine : {false, true}) {
    const pm::PlaneSearch search(p, v.left, v.right,
                                 refine ? pm::SearchOptions() : propagationOnly());
    const int idx = 15 * 80 + 40;
    frontoParallelAround(v.left, idx, 7.f, 9.f, 7.f);  // the left neighbour has the true plane
    pm::WindowCache cache;
    search.processPixel(40, 15, true, 0, cache);
    if (refine) {
      EXPECT_NEAR(v.left.planes[idx].at(40.f, 15.f), 9.f, 0.1f);  // refined around it
    } else {
      EXPECT_EQ(v.left.planes[idx].c, 9.f);  // exactly the neighbour's plane
      EXPECT_EQ(v.left.planes[idx].a, 0.f);
    }
  }
}

TEST(PatchMatchSearch, PolishWithoutRefinementStepsDOnlyAndKeepsTheNormal) {
  // fine_refine: false at full size: propagation, then the sub-pixel step alone.
  const lsf::test::PlaneScene s = lsf::test::PlaneScene::make(80, 30, 0.0, 0.0, 9.0, 5);
  lsf::PatchMatchParams p = params3x3();
  p.window_radius = 3;
  Views v = prepare({s.left}, {s.right}, p);
  pm::SearchOptions polish = propagationOnly();
  polish.subpixel = true;
  const pm::PlaneSearch search(p, v.left, v.right, polish);
  const int idx = 15 * 80 + 40;
  frontoParallelAround(v.left, idx, 7.f, 9.06f, 7.f);  // the left neighbour is 0.06 px off
  pm::WindowCache cache;
  search.processPixel(40, 15, true, 0, cache);
  const pm::Plane& got = v.left.planes[idx];
  EXPECT_LT(std::abs(got.c - 9.f), 0.6f * 0.06f);  // taken from the neighbour, then stepped
  EXPECT_NE(got.c, 9.06f);
  EXPECT_EQ(got.a, 0.f);  // no random refinement: the normal is the neighbour's
  EXPECT_EQ(got.b, 0.f);
}

TEST(PatchMatchSearch, ATolerantPropagationSkipsNearCandidatesAndBuildsNoWindowForThem) {
  // The full-size right view (it serves the left-right check only): candidates within the
  // tolerance of the current plane are not evaluated.
  const lsf::test::PlaneScene s = lsf::test::PlaneScene::make(80, 30, 0.0, 0.0, 9.2, 5);
  lsf::PatchMatchParams p = params3x3();
  p.window_radius = 3;
  Views v = prepare({s.left}, {s.right}, p);
  const int idx = 15 * 80 + 40;
  for (const float tolerance : {0.f, 0.25f, 0.1f}) {
    pm::SearchOptions o = propagationOnly();
    o.tolerance = tolerance;
    const pm::PlaneSearch search(p, v.left, v.right, o);
    frontoParallelAround(v.left, idx, 9.f, 9.2f, 9.f);  // the left one true, 0.2 px away
    pm::WindowCache cache;
    search.processPixel(40, 15, true, 0, cache);
    if (tolerance == 0.25f) {
      EXPECT_EQ(v.left.planes[idx].c, 9.f);           // kept: 0.2 px is within the tolerance
      EXPECT_EQ(v.left.cost[idx], pm::kUnknownCost);  // no window was built, no cost computed
    } else {
      EXPECT_EQ(v.left.planes[idx].c, 9.2f) << tolerance;  // evaluated and taken
      EXPECT_NE(v.left.cost[idx], pm::kUnknownCost) << tolerance;
    }
  }
}

TEST(PatchMatchViewPropagation, AGoodLeftPlaneReachesItsMatchInTheRightView) {
  const lsf::test::PlaneScene s = lsf::test::PlaneScene::make(80, 20, 0.0, 0.0, 6.0, 9);
  lsf::PatchMatchParams p = params3x3();
  p.window_radius = 2;
  Views v = prepare({s.left}, {s.right}, p);
  const pm::PlaneSearch right_search(p, v.right, v.left);
  for (auto& plane : v.left.planes) plane = pm::Plane{0.f, 0.f, 6.f};
  for (size_t i = 0; i < v.right.planes.size(); ++i) {
    v.right.planes[i] = pm::Plane{0.f, 0.f, 20.f};
    v.right.cost[i] = std::numeric_limits<float>::max();
  }
  pm::propagateView(v.left, right_search, v.right, p, true);
  // Right pixel 40 is matched by left pixel 46 and takes its plane.
  EXPECT_FLOAT_EQ(v.right.planes[10 * 80 + 40].at(40.f, 10.f), 6.f);
  EXPECT_LT(v.right.cost[10 * 80 + 40], 1e-2f);
  // Right pixels no left pixel maps to (x >= 80 - 6) keep theirs.
  EXPECT_FLOAT_EQ(v.right.planes[10 * 80 + 78].c, 20.f);
}

TEST(PatchMatchViewPropagation, OfferedPlanesAreTriedWhenTheSweepVisitsAndTheNearerSurfaceWins) {
  const lsf::test::PlaneScene s = lsf::test::PlaneScene::make(80, 20, 0.0, 0.0, 6.0, 9);
  lsf::PatchMatchParams p = params3x3();
  p.window_radius = 2;
  Views v = prepare({s.left}, {s.right}, p);
  const pm::PlaneSearch right_search(p, v.right, v.left, propagationOnly());
  for (auto& plane : v.left.planes) plane = pm::Plane{0.f, 0.f, 6.f};
  // Left pixel 44 (d 4) and left pixel 46 (d 6) both match right pixel 40: 46 is the nearer.
  v.left.planes[10 * 80 + 44] = pm::Plane{0.f, 0.f, 4.f};
  for (size_t i = 0; i < v.right.planes.size(); ++i) {
    v.right.planes[i] = pm::Plane{0.f, 0.f, 20.f};
    v.right.cost[i] = pm::kUnknownCost;
  }
  pm::offerView(v.left, right_search, v.right, p, true);
  const int idx = 10 * 80 + 40;
  ASSERT_TRUE(v.right.offered[idx]);
  EXPECT_EQ(v.right.offer[idx].c, 6.f);
  EXPECT_EQ(v.right.planes[idx].c, 20.f);       // nothing evaluated yet
  EXPECT_FALSE(v.right.offered[10 * 80 + 78]);  // no left pixel maps there
  pm::WindowCache cache;
  right_search.processPixel(40, 10, true, 0, cache);
  EXPECT_EQ(v.right.planes[idx].c, 6.f);
  EXPECT_LT(v.right.cost[idx], 1e-2f);
  EXPECT_FALSE(v.right.offered[idx]);  // withdrawn once tried
}
