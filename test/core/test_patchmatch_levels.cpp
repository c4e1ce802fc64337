// PatchMatch's coarse start, with exact answers (coarse_to_fine.h): the guide from the half-size
// level, the planes and views between levels, and the left-right check and filling at the levels
// (post_processing.h). The post-processing steps alone: test_patchmatch_post_processing.cpp.
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/patchmatch.h"
#include "lidar_stereo_fusion/core/patchmatch/coarse_to_fine.h"
#include "lidar_stereo_fusion/core/patchmatch/post_processing.h"
#include "patchmatch_steps_util.h"
#include "test_scenes.h"

namespace lsf = lidar_stereo_fusion;
namespace pm = lidar_stereo_fusion::patchmatch;

using lidar_stereo_fusion::test::params3x3;
using lidar_stereo_fusion::test::prepare;
using lidar_stereo_fusion::test::uniform;
using lidar_stereo_fusion::test::Views;

namespace {

/// 6x4 uniform views whose row 2 lies between scan lines (bounded) and whose pixel (0, 3) is
/// locked to the prior, with the guide d = 7 everywhere.
Views guided6x4(const lsf::PatchMatchParams& p) {
  lsf::ScanLineBounds b;
  b.lo = cv::Mat1f::zeros(4, 6);
  b.hi = cv::Mat1f::zeros(4, 6);
  b.range = cv::Mat1f::zeros(4, 6);
  for (int x = 0; x < 6; ++x) b.hi(2, x) = b.lo(2, x) = 5.f;
  cv::Mat1f prior = cv::Mat1f::zeros(4, 6), conf = cv::Mat1f::zeros(4, 6);
  prior(3, 0) = 5.f;
  conf(3, 0) = 1.f;
  Views v = prepare({uniform(6, 4, 30), prior, b, conf}, {uniform(6, 4, 30)}, p);
  pm::setGuide(std::vector<pm::Plane>(24, pm::Plane{0.f, 0.f, 7.f}), p, v.left);
  return v;
}

}  // namespace

TEST(PatchMatchCoarseStart, UnboundedPixelsAreSettledByTheGuideUnlessAsked) {
  lsf::PatchMatchParams p = params3x3();
  p.full_size_unbounded = false;
  Views v = guided6x4(p);
  EXPECT_EQ(v.left.locked[0 * 6 + 1], pm::kSettledByGuide);
  EXPECT_EQ(v.left.locked[2 * 6 + 1], 0);  // bounded: searched
  EXPECT_EQ(v.left.locked[3 * 6 + 0], pm::kLockedToPrior);
  const pm::PlaneSearch search(p, v.left, v.right);
  pm::Rng rng(3);
  EXPECT_EQ(search.initialPlane(1, 0, rng).c, 7.f);
  p.full_size_unbounded = true;
  Views w = guided6x4(p);
  EXPECT_EQ(w.left.locked[0 * 6 + 1], 0);
}

TEST(PatchMatchCoarseStart, FinerThanUnboundedScaleUnboundedPixelsKeepTheGuideAsItIs) {
  lsf::PatchMatchParams p = params3x3();
  p.unbounded_scale = 2;
  p.full_size_unbounded = false;  // unbounded_scale wins: kept, not polished
  Views v = guided6x4(p);
  EXPECT_EQ(v.left.locked[0 * 6 + 1], pm::kKeptFromGuide);
  EXPECT_EQ(v.left.locked[2 * 6 + 1], 0);  // bounded: searched
  EXPECT_EQ(v.left.locked[3 * 6 + 0], pm::kLockedToPrior);
  pm::SearchOptions polish;
  polish.refine = false;
  polish.subpixel = true;
  const pm::PlaneSearch search(p, v.left, v.right, polish);
  pm::Rng rng(3);
  EXPECT_EQ(search.initialPlane(1, 0, rng).c, 7.f);
  // Neither propagated to nor polished: no window, the plane and cost as they were.
  v.left.planes[0 * 6 + 0] = pm::Plane{0.f, 0.f, 9.f};
  v.left.planes[0 * 6 + 1] = pm::Plane{0.f, 0.f, 7.f};
  v.left.cost[0 * 6 + 1] = 3.f;
  pm::WindowCache cache;
  search.processPixel(1, 0, true, 0, cache);
  EXPECT_EQ(v.left.planes[0 * 6 + 1].c, 7.f);
  EXPECT_EQ(v.left.cost[0 * 6 + 1], 3.f);
  EXPECT_EQ(cache.count, 0);
  // The levels below search them down to unbounded_scale: 4 -> the 1/2 level keeps the 1/4
  // level's planes, which searches them.
  lsf::PatchMatchParams two_levels;  // of 2
  two_levels.unbounded_scale = 4;
  const lsf::PatchMatchParams half = pm::coarseParams(two_levels);
  EXPECT_EQ(half.unbounded_scale, 2);
  EXPECT_EQ(pm::coarseParams(half).unbounded_scale, 1);
  two_levels.unbounded_scale = 2;
  EXPECT_EQ(pm::coarseParams(two_levels).unbounded_scale, 1);
}

TEST(PatchMatchCoarseStart, AtUnboundedScale2StereoOnlyPixelsAreTheHalfSizePlanes) {
  // No LiDAR: every pixel is unbounded, so the full-size planes are exactly the 1/2-size level's,
  // up-sampled (the fill changes the disparity of inconsistent pixels, not the planes).
  const lsf::test::PlaneScene s = lsf::test::PlaneScene::make(96, 48, 0.05, 0.0, 6.0, 4);
  for (const bool intermediate_refine : {true, false}) {
    lsf::PatchMatchParams p;
    p.max_disparity = 16;
    p.unbounded_scale = 2;
    p.intermediate_refine = intermediate_refine;
    p.skip_inconsistent = false;  // else inconsistent pixels take their neighbour's plane
    p.num_threads = 1;
    const lsf::PatchMatchResult full = lsf::PatchMatchStereo(p).compute({s.left}, {s.right});
    lsf::PatchMatchStereo half_level(pm::coarseParams(p));
    const lsf::PatchMatchResult half =
        half_level.compute(pm::downsampleView({s.left}, 2), pm::downsampleView({s.right}, 2));
    // A stand-alone solver is not an intermediate level, so it refines its right view whatever
    // intermediate_refine says: the planes are compared only where that is the same (true).
    const std::vector<pm::Plane> up = pm::upsamplePlanes(half.planes, 2, s.left.size());
    int same = 0;
    for (int y = 0; y < 48; ++y) {
      for (int x = 0; x < 96; ++x) {
        const cv::Vec3f& q = full.planes(y, x);
        const pm::Plane& e = up[y * 96 + x];
        same += q[0] == e.a && q[1] == e.b && q[2] == e.c;
      }
    }
    if (intermediate_refine) {
      EXPECT_EQ(same, 96 * 48);
    }
    // The slanted plane is found either way (d = 6 + 0.05 x), less precisely than at full size
    // (0.17 px mean error; 0.31 px when the 1/2 level only propagates).
    double error = 0.0;
    for (int y = 8; y < 40; ++y) {
      for (int x = 24; x < 88; ++x) error += std::abs(full.disparity(y, x) - s.disparity(x, y));
    }
    EXPECT_LT(error / (32 * 64), intermediate_refine ? 0.25 : 0.4)
        << "intermediate_refine " << intermediate_refine;
  }
}

TEST(PatchMatchCoarseStart, AtSearchScale2FullSizeUpsamplesTheCheckedAndFilledHalfSizeLevel) {
  // A slanted plane with a locked prior row: full size does not search. Every pixel is the 1/2
  // level's plane evaluated at full size, the prior where it is locked, or twice the level's
  // filled disparity where its left-right check failed.
  const lsf::test::PlaneScene s = lsf::test::PlaneScene::make(96, 48, 0.05, 0.0, 6.0, 4);
  cv::Mat1f prior = cv::Mat1f::zeros(48, 96), conf = cv::Mat1f::zeros(48, 96);
  for (int x = 0; x < 96; ++x) {
    prior(20, x) = static_cast<float>(s.disparity(x, 20));
    conf(20, x) = 1.f;
  }
  lsf::PatchMatchParams p;
  p.max_disparity = 16;
  p.search_scale = 2;
  p.num_threads = 1;
  const lsf::ViewInput left(s.left, prior, {}, conf), right(s.right);
  const lsf::PatchMatchResult full = lsf::PatchMatchStereo(p).compute(left, right);
  const lsf::PatchMatchParams half_params = pm::coarseParams(p);
  EXPECT_TRUE(half_params.lr_check);  // the level that fills
  EXPECT_EQ(half_params.lr_max_diff, p.lr_max_diff / 2);
  EXPECT_EQ(half_params.search_scale, 1);
  const lsf::PatchMatchResult half =
      lsf::PatchMatchStereo(half_params)
          .compute(pm::downsampleView(left, 2), pm::downsampleView(right, 2));
  const std::vector<pm::Plane> up = pm::upsamplePlanes(half.planes, 2, s.left.size());
  int checked = 0, filled = 0;
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 96; ++x) {
      float expected = up[y * 96 + x].at(static_cast<float>(x), static_cast<float>(y));
      if (y == 20) {
        expected = prior(20, x);  // locked
        EXPECT_EQ(full.inconsistent(y, x), 0);
      } else if (half.inconsistent(y / 2, x / 2)) {
        expected = 2.f * half.disparity(y / 2, x / 2);
        ++filled;
      }
      EXPECT_FLOAT_EQ(full.disparity(y, x), std::max(0.f, expected)) << x << ", " << y;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 96 * 48);
  EXPECT_GT(filled, 0);  // the right border, hidden in the right view
}

TEST(PatchMatchCoarseStart, WithoutPlaneMapsTheDisparityAndTheCheckAreTheSame) {
  // The fusion pipeline reads the disparity alone (setPlanesOutput(false)): the search, levels
  // below included, is the same, only the plane maps are not returned.
  const lsf::test::PlaneScene s = lsf::test::PlaneScene::make(96, 48, 0.05, 0.0, 6.0, 4);
  for (const int search_scale : {1, 2}) {
    lsf::PatchMatchParams p;
    p.max_disparity = 16;
    p.search_scale = search_scale;
    lsf::PatchMatchStereo with(p), without(p);
    without.setPlanesOutput(false);
    const lsf::PatchMatchResult a = with.compute({s.left}, {s.right});
    const lsf::PatchMatchResult b = without.compute({s.left}, {s.right});
    EXPECT_FALSE(a.planes.empty());
    EXPECT_TRUE(b.planes.empty());
    EXPECT_TRUE(b.right_planes.empty());
    EXPECT_EQ(cv::norm(a.disparity, b.disparity, cv::NORM_INF), 0.0) << search_scale;
    EXPECT_EQ(cv::norm(a.inconsistent, b.inconsistent, cv::NORM_INF), 0.0) << search_scale;
  }
}

TEST(PatchMatchCoarseStart, InconsistentPixelsWithoutBoundsAreLeftToTheFill) {
  const lsf::PatchMatchParams p = params3x3();
  Views v = guided6x4(p);
  cv::Mat1b inconsistent(4, 6, uchar(255));
  inconsistent(1, 4) = 0;
  pm::leaveToFill(inconsistent, v.left);
  EXPECT_EQ(v.left.locked[0 * 6 + 1], pm::kLeftToFill);
  EXPECT_EQ(v.left.locked[1 * 6 + 4], 0);                   // consistent: searched
  EXPECT_EQ(v.left.locked[2 * 6 + 1], 0);                   // bounded: searched
  EXPECT_EQ(v.left.locked[3 * 6 + 0], pm::kLockedToPrior);  // the prior's, kept
  pm::SearchOptions polish;
  polish.refine = false;
  polish.subpixel = true;
  const pm::PlaneSearch search(p, v.left, v.right, polish);
  pm::Rng rng(3);
  EXPECT_EQ(search.initialPlane(1, 0, rng).c, 7.f);  // the level below's plane
  // Not searched: it takes the plane before it in the sweep, whose cost here is unknown.
  v.left.planes[0 * 6 + 0] = pm::Plane{0.f, 0.f, 9.f};
  v.left.planes[0 * 6 + 2] = pm::Plane{0.f, 0.f, 5.f};
  pm::WindowCache cache;
  search.processPixel(1, 0, true, 0, cache);
  EXPECT_EQ(v.left.planes[0 * 6 + 1].c, 9.f);
  EXPECT_EQ(v.left.cost[0 * 6 + 1], pm::kUnknownCost);
  search.processPixel(1, 0, false, 1, cache);
  EXPECT_EQ(v.left.planes[0 * 6 + 1].c, 5.f);
  EXPECT_EQ(cache.count, 0);  // no window was built
  v.left.planes[0 * 6 + 0] = pm::Plane{0.f, 0.f, 7.f};
  search.processPixel(0, 0, true, 0, cache);  // nothing before it: keeps its plane
  EXPECT_EQ(v.left.planes[0 * 6 + 0].c, 7.f);
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

TEST(PatchMatchCoarseStart, MaskScalesToFullSizeLikeThePlanes) {
  // Full pixel (x, y) takes coarse pixel (x / 2, y / 2); an odd size repeats the last coarse one.
  cv::Mat1b coarse(2, 3, uchar(0));
  coarse(0, 1) = 255;
  coarse(1, 2) = 255;
  const cv::Mat1b full = pm::upsampleMask(coarse, 2, cv::Size(5, 3));
  const uchar expected[3][5] = {{0, 0, 255, 255, 0}, {0, 0, 255, 255, 0}, {0, 0, 0, 0, 255}};
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 5; ++x) EXPECT_EQ(full(y, x), expected[y][x]) << x << ", " << y;
  }
}

namespace {

/// A textured box at disparity 12 (columns [40, 70) of the left view) before a textured
/// background at 4: the background columns [32, 40) of the left view are hidden in the right.
struct BoxScene {
  cv::Mat left, right;
  static constexpr int kBox0 = 40, kBox1 = 70;
  static constexpr double kBox = 12, kBack = 4;
  static BoxScene make(int width, int height) {
    const lsf::test::Texture back(5), box(6);
    BoxScene s{cv::Mat(height, width, CV_8UC3), cv::Mat(height, width, CV_8UC3)};
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const bool in_box = x >= kBox0 && x < kBox1;
        s.left.at<cv::Vec3b>(y, x) = in_box ? box.at(x, y) : back.at(x, y);
        const double xl = x + kBox;  // right pixel x sees the box if the box is at x + 12
        s.right.at<cv::Vec3b>(y, x) =
            xl >= kBox0 && xl < kBox1 ? box.at(xl, y) : back.at(x + kBack, y);
      }
    }
    return s;
  }
};

/// Stereo alone (colour and gradient only), the box scene's disparity range.
lsf::PatchMatchParams boxParams() {
  lsf::PatchMatchParams p;
  p.alpha = 0.5;
  p.beta = 0.5;
  p.gamma = 0.0;
  p.max_disparity = 24;
  return p;
}

}  // namespace

TEST(PatchMatchCoarseStart, TheLeftRightCheckRunsAtHalfSizeUnlessAsked) {
  const BoxScene s = BoxScene::make(128, 64);
  lsf::PatchMatchParams p = boxParams();
  for (const int variant : {0, 1, 2}) {  // 2: the 1/2 level only propagates (the live preset)
    const bool fine_lr_check = variant == 1;
    p.fine_lr_check = fine_lr_check;
    p.intermediate_refine = variant != 2;
    lsf::PatchMatchStereo matcher(p);
    const lsf::PatchMatchResult r = matcher.compute({s.left}, {s.right});
    // The full-size right view is searched only for a full-size check.
    EXPECT_EQ(r.right_disparity.empty(), !fine_lr_check);
    // Either check finds the hidden strip (inner columns; half-size pixels straddle its ends) and
    // little else inside the image. (How the strip is filled is the fill's: its window reaches
    // the box, whose texture weighs as much as the background's here.)
    int hidden = 0, flagged_hidden = 0, seen = 0, flagged_seen = 0;
    for (int y = 8; y < 56; ++y) {
      for (int x = 24; x < 104; ++x) {
        const bool bad = r.inconsistent(y, x) != 0;
        if (x >= 34 && x < 38) {
          ++hidden;
          flagged_hidden += bad;
        } else if (x < 30 || (x >= 42 && x < 68) || x >= 72) {
          ++seen;
          flagged_seen += bad;
        }
      }
    }
    EXPECT_GT(flagged_hidden, 0.9 * hidden) << "variant " << variant;
    EXPECT_LT(flagged_seen, 0.02 * seen) << "variant " << variant;
  }
}

TEST(PatchMatchCoarseStart, SkippingInconsistentPixelsKeepsForegroundEdges) {
  // Stereo only, no scan-line bounds: every pixel the 1/4-size check flags could be skipped at
  // 1/2 size. The 1/4-size pixels at the box's edges straddle them; skipping those too put the
  // background on 2-4 columns of the box (mean error 0.25 px over the visible pixels).
  const BoxScene s = BoxScene::make(128, 64);
  lsf::PatchMatchParams p = boxParams();
  for (const bool skip : {false, true}) {
    p.skip_inconsistent = skip;
    lsf::PatchMatchStereo matcher(p);
    const lsf::PatchMatchResult r = matcher.compute({s.left}, {s.right});
    double error = 0.0;
    int seen = 0;
    for (int y = 8; y < 56; ++y) {
      for (int x = 24; x < 104; ++x) {
        if (x >= 32 && x < 40) continue;  // hidden in the right view
        const double truth =
            x >= BoxScene::kBox0 && x < BoxScene::kBox1 ? BoxScene::kBox : BoxScene::kBack;
        error += std::abs(r.disparity(y, x) - truth);
        ++seen;
      }
    }
    EXPECT_LT(error / seen, 0.2) << "skip_inconsistent " << skip;
  }
}
