// PatchMatch, step by step, with exact answers: the plane xi (patchmatch/plane.h), the cost C with
// w and phi (cost.h), the search steps (propagation.h), view propagation, the left-right check and
// filling (post_processing.h) and the coarse start (coarse_to_fine.h).
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/patchmatch/coarse_to_fine.h"
#include "lidar_stereo_fusion/core/patchmatch/cost.h"
#include "lidar_stereo_fusion/core/patchmatch/post_processing.h"
#include "lidar_stereo_fusion/core/patchmatch/propagation.h"
#include "test_scenes.h"

namespace lsf = lidar_stereo_fusion;
namespace pm = lidar_stereo_fusion::patchmatch;

namespace {

/// Uniform images: every support weight is 1 and every gradient 0.
cv::Mat uniform(int w, int h, uchar value) {
  return cv::Mat(h, w, CV_8UC3, cv::Scalar::all(value));
}

lsf::PatchMatchParams params3x3() {
  lsf::PatchMatchParams p;  // defaults: alpha 0.01, beta 0.09, gamma 0.9, weighted
  p.window_radius = 1;
  p.window_stride = 1;
  p.coarse_scale = 1;
  return p;
}

struct Views {
  pm::ViewState left, right;
};

/// A view searched by propagation alone (no plane refinement).
pm::SearchOptions propagationOnly() {
  pm::SearchOptions o;
  o.refine = false;
  return o;
}

Views prepare(const lsf::ViewInput& l, const lsf::ViewInput& r, const lsf::PatchMatchParams& p) {
  Views v;
  pm::prepareView(l, p, -1.f, v.left);
  pm::prepareView(r, p, +1.f, v.right);
  return v;
}

float costOf(const pm::MatchingCost& cost, int x, int y, const pm::Plane& plane) {
  pm::WindowCache cache;
  cost.buildWindow(x, y, cache);
  return cost.aggregate(cache, plane, std::numeric_limits<float>::max());
}

}  // namespace

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
    v.left.planes[idx] = pm::Plane{0.f, 0.f, 7.f};
    v.left.cost[idx] = pm::kUnknownCost;
    v.left.planes[idx - 1] = pm::Plane{0.f, 0.f, 9.f};  // the left neighbour has the true plane
    v.left.planes[idx - 80] = pm::Plane{0.f, 0.f, 7.f};
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
  v.left.planes[idx] = pm::Plane{0.f, 0.f, 7.f};
  v.left.cost[idx] = pm::kUnknownCost;
  v.left.planes[idx - 1] = pm::Plane{0.f, 0.f, 9.06f};  // the neighbour is 0.06 px off
  v.left.planes[idx - 80] = pm::Plane{0.f, 0.f, 7.f};
  pm::WindowCache cache;
  search.processPixel(40, 15, true, 0, cache);
  const pm::Plane& got = v.left.planes[idx];
  EXPECT_LT(std::abs(got.c - 9.f), 0.6f * 0.06f);  // taken from the neighbour, then stepped
  EXPECT_NE(got.c, 9.06f);
  EXPECT_EQ(got.a, 0.f);  // no random refinement: the normal is the neighbour's
  EXPECT_EQ(got.b, 0.f);
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
  pm::fillHoles(v.left, bad, 1, 10.f, 0.5f, 192.f, disparity, 1);
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
  pm::fillHoles(v.left, bad, 2, 10.f, 0.5f, 192.f, disparity, 1);
  for (int x = 5; x < 9; ++x) EXPECT_LE(disparity(0, x), 192.f) << x;
  EXPECT_EQ(disparity(0, 8), 0.f);    // its window (pixels 6, 8) holds no fill: left empty
  EXPECT_EQ(disparity(0, 5), 140.f);  // the median of its window: pixels 3 (140) and 5 (180)
}

TEST(PatchMatchCoarseStart, UnboundedPixelsAreSettledByTheGuideUnlessAsked) {
  lsf::PatchMatchParams p = params3x3();
  p.full_size_unbounded = false;
  lsf::ScanLineBounds b;
  b.lo = cv::Mat1f::zeros(4, 6);
  b.hi = cv::Mat1f::zeros(4, 6);
  b.range = cv::Mat1f::zeros(4, 6);
  for (int x = 0; x < 6; ++x) b.hi(2, x) = b.lo(2, x) = 5.f;  // row 2 lies between scan lines
  cv::Mat1f prior = cv::Mat1f::zeros(4, 6), conf = cv::Mat1f::zeros(4, 6);
  prior(3, 0) = 5.f;
  conf(3, 0) = 1.f;  // one pixel locked to the prior
  Views v = prepare({uniform(6, 4, 30), prior, b, conf}, {uniform(6, 4, 30)}, p);
  pm::setGuide(std::vector<pm::Plane>(24, pm::Plane{0.f, 0.f, 7.f}), p, v.left);
  EXPECT_EQ(v.left.locked[0 * 6 + 1], pm::kSettledByGuide);
  EXPECT_EQ(v.left.locked[2 * 6 + 1], 0);  // bounded: searched
  EXPECT_EQ(v.left.locked[3 * 6 + 0], pm::kLockedToPrior);
  const pm::PlaneSearch search(p, v.left, v.right);
  pm::Rng rng(3);
  EXPECT_EQ(search.initialPlane(1, 0, rng).c, 7.f);
  p.full_size_unbounded = true;
  Views w = prepare({uniform(6, 4, 30), prior, b, conf}, {uniform(6, 4, 30)}, p);
  pm::setGuide(std::vector<pm::Plane>(24, pm::Plane{0.f, 0.f, 7.f}), p, w.left);
  EXPECT_EQ(w.left.locked[0 * 6 + 1], 0);
}

TEST(PatchMatchCoarseStart, PlanesScaleToFullSizeAndViewsReduceExactly) {
  cv::Mat3f coarse(2, 3, cv::Vec3f(0.f, 0.f, 0.f));
  coarse(1, 2) = cv::Vec3f(0.5f, 0.25f, 3.f);
  const std::vector<pm::Plane> full = pm::upsamplePlanes(coarse, 4, cv::Size(12, 8));
  // Full pixel (9, 5) lies in coarse pixel (2, 1), whose centre is at full (9.5, 5.5) = coarse
  // (2, 1): d_full(9.5, 5.5) = 4 d_coarse(2, 1) = 4 (1 + 0.25 + 3) = 17.
  const pm::Plane& p = full[5 * 12 + 9];
  EXPECT_FLOAT_EQ(p.at(9.5f, 5.5f), 17.f);
  EXPECT_FLOAT_EQ(p.a, 0.5f);
  lsf::ViewInput in{uniform(12, 8, 7), cv::Mat1f(8, 12, 8.f), {}, cv::Mat1f(8, 12, 0.75f)};
  const lsf::ViewInput small = pm::downsampleView(in, 4);
  EXPECT_EQ(small.image.size(), cv::Size(3, 2));
  EXPECT_EQ(small.prior(1, 1), 2.f);
  EXPECT_EQ(small.confidence(1, 1), 0.75f);
  lsf::PatchMatchParams params;
  params.coarse_scale = 4;
  params.coarse_levels = 1;
  const lsf::PatchMatchParams c = pm::coarseParams(params);
  EXPECT_EQ(c.window_radius, 2);
  EXPECT_EQ(c.window_stride, 1);
  EXPECT_EQ(c.max_disparity, params.max_disparity / 4);
  EXPECT_EQ(c.coarse_scale, 1);
  EXPECT_FALSE(c.lr_check);
  // Two levels of 2: the level below is itself a coarse start of one level.
  params.coarse_scale = 2;
  params.coarse_levels = 2;
  const lsf::PatchMatchParams half = pm::coarseParams(params);
  EXPECT_EQ(half.window_radius, 4);
  EXPECT_EQ(half.coarse_scale, 2);
  EXPECT_EQ(half.coarse_levels, 1);
  EXPECT_TRUE(half.full_size_unbounded);
  EXPECT_EQ(pm::coarseParams(half).window_radius, 2);
}

TEST(PatchMatchCoarseStart, LeftRightCheckWithoutViewPropagationRuns) {
  // The coarse levels have no left-right check: without view propagation they have no right
  // view, and the full-size right view starts without a guide.
  const lsf::test::PlaneScene s = lsf::test::PlaneScene::make(96, 48, 0.0, 0.0, 5.0, 4);
  lsf::PatchMatchParams p;
  p.view_propagation = false;
  p.lr_check = true;
  p.max_disparity = 16;
  lsf::PatchMatchStereo pm(p);
  const lsf::PatchMatchResult r = pm.compute({s.left}, {s.right});
  EXPECT_EQ(r.disparity.size(), s.left.size());
  EXPECT_NEAR(r.disparity(24, 48), 5.f, 0.5f);
}
