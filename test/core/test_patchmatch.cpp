// Guided PatchMatch on synthetic stereo pairs with exactly known disparity.
#include <string>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "lidar_stereo_fusion/core/patchmatch.h"
#include "lidar_stereo_fusion/core/patchmatch/coarse_to_fine.h"
#include "test_scenes.h"

namespace lsf = lidar_stereo_fusion;
using lsf::test::PlaneScene;

namespace {

/// Mean absolute disparity error over pixels whose match is inside the right image, away from
/// the window-sized border.
double meanError(const cv::Mat1f& est, const PlaneScene& s, int border) {
  double sum = 0;
  int n = 0;
  for (int y = border; y < est.rows - border; ++y) {
    for (int x = border; x < est.cols - border; ++x) {
      const double gt = s.disparity(x, y);
      if (x - gt < border) continue;
      sum += std::abs(est(y, x) - gt);
      ++n;
    }
  }
  return n ? sum / n : 1e9;
}

lsf::PatchMatchParams stereoOnly() {
  lsf::PatchMatchParams p;
  p.alpha = 0.5;
  p.beta = 0.5;
  p.gamma = 0.0;
  p.init_from_prior = false;
  p.use_lidar_bounds = false;
  p.min_disparity = 1;
  p.max_disparity = 48;
  p.iterations = 3;
  return p;
}

}  // namespace

TEST(PatchMatch, RecoversFrontoParallelPlane) {
  const uint64_t seed = 7;
  const PlaneScene s = PlaneScene::make(240, 120, 0.0, 0.0, 20.3, seed);
  lsf::PatchMatchStereo pm(stereoOnly());
  const auto r = pm.compute({s.left, cv::Mat1f(), {}}, {s.right, cv::Mat1f(), {}});
  EXPECT_LT(meanError(r.disparity, s, 8), 0.05) << "seed " << seed;
}

TEST(PatchMatch, SmoothingKeepsHalfPixelDisparitiesFromLockingToWholePixels) {
  // Linear interpolation of the other view attenuates fine texture most half-way between pixels,
  // which pulls the cost's minimum toward whole-pixel disparities; image_smoothing band-limits
  // the images first. A plane at a half-pixel disparity, with and without it.
  const uint64_t seed = 7;
  const PlaneScene s = PlaneScene::make(240, 120, 0.0, 0.0, 20.5, seed);
  auto p = stereoOnly();
  lsf::PatchMatchStereo smoothed(p);
  const double with = meanError(
      smoothed.compute({s.left, cv::Mat1f(), {}}, {s.right, cv::Mat1f(), {}}).disparity, s, 8);
  p.image_smoothing = 0.0;
  lsf::PatchMatchStereo raw(p);
  const double without =
      meanError(raw.compute({s.left, cv::Mat1f(), {}}, {s.right, cv::Mat1f(), {}}).disparity, s, 8);
  EXPECT_LT(with, 0.05);
  EXPECT_LT(with, 0.5 * without);
}

TEST(PatchMatch, RecoversSlantedPlane) {
  // d = 0.08 x + 0.05 y + 6: a ground-like slant in both directions, on 8 random textures (one
  // texture's median slope moves by up to 0.008 with the random search: 3 of 12 seeds fail a
  // 0.005 bound with the square window, 5 with the round one, while the mean over seeds stays
  // within 0.003 for both).
  constexpr int kSeeds = 8;
  double error = 0, mean_a = 0, mean_b = 0;
  for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const PlaneScene s = PlaneScene::make(240, 120, 0.08, 0.05, 6.0, seed);
    lsf::PatchMatchStereo pm(stereoOnly());
    const auto r = pm.compute({s.left, cv::Mat1f(), {}}, {s.right, cv::Mat1f(), {}});
    error += meanError(r.disparity, s, 8) / kSeeds;
    // The recovered planes carry the slant, not only the disparity: median slopes over the
    // interior.
    std::vector<float> as, bs;
    for (int y = 10; y < 110; ++y) {
      for (int x = 40; x < 230; ++x) {
        as.push_back(r.planes(y, x)[0]);
        bs.push_back(r.planes(y, x)[1]);
      }
    }
    std::nth_element(as.begin(), as.begin() + as.size() / 2, as.end());
    std::nth_element(bs.begin(), bs.begin() + bs.size() / 2, bs.end());
    EXPECT_NEAR(as[as.size() / 2], 0.08, 0.01) << "seed " << seed;
    EXPECT_NEAR(bs[bs.size() / 2], 0.05, 0.01) << "seed " << seed;
    mean_a += as[as.size() / 2] / kSeeds;
    mean_b += bs[bs.size() / 2] / kSeeds;
  }
  EXPECT_LT(error, 0.05);
  EXPECT_NEAR(mean_a, 0.08, 0.004);
  EXPECT_NEAR(mean_b, 0.05, 0.004);
}

TEST(PatchMatch, FrontParallelModeKeepsNormalsFlat) {
  const PlaneScene s = PlaneScene::make(160, 80, 0.0, 0.0, 12.0, 3);
  auto p = stereoOnly();
  p.slanted = false;
  lsf::PatchMatchStereo pm(p);
  const auto r = pm.compute({s.left, cv::Mat1f(), {}}, {s.right, cv::Mat1f(), {}});
  for (int y = 0; y < r.planes.rows; ++y) {
    for (int x = 0; x < r.planes.cols; ++x) {
      ASSERT_EQ(r.planes(y, x)[0], 0.f);
      ASSERT_EQ(r.planes(y, x)[1], 0.f);
    }
  }
  EXPECT_LT(meanError(r.disparity, s, 8), 0.1);
}

TEST(PatchMatch, LidarPriorCarriesTexturelessRegion) {
  // A flat grey image: stereo alone cannot match; the exact prior must carry the result.
  cv::Mat left(80, 160, CV_8UC3, cv::Scalar(90, 90, 90));
  cv::Mat right = left.clone();
  cv::Mat1f prior(80, 160, 15.0f);
  lsf::PatchMatchParams p;  // paper defaults: alpha 0.1, beta 0, gamma 0.9
  p.lr_check = false;
  lsf::PatchMatchStereo pm(p);
  const auto r = pm.compute({left, prior, {}}, {right, cv::Mat1f(80, 160, 15.0f), {}});
  for (int y = 5; y < 75; ++y) {
    for (int x = 20; x < 155; ++x) ASSERT_NEAR(r.disparity(y, x), 15.0f, 0.05f) << x << "," << y;
  }
}

TEST(PatchMatch, ScanLineBoundsLimitTheSearch) {
  // Wrong colours everywhere except at disparity 30; bounds [9, 11] forbid 30.
  const PlaneScene s = PlaneScene::make(160, 80, 0.0, 0.0, 30.0, 5);
  lsf::PatchMatchParams p = stereoOnly();
  p.use_lidar_bounds = true;
  p.lr_check = false;
  p.view_propagation = false;
  lsf::ScanLineBounds b;
  b.lo = cv::Mat1f(80, 160, 9.f);
  b.hi = cv::Mat1f(80, 160, 11.f);
  b.range = cv::Mat1f(80, 160, 2.f);
  lsf::PatchMatchStereo pm(p);
  const auto r = pm.compute({s.left, cv::Mat1f(), b}, {s.right, cv::Mat1f(), b});
  double min_v, max_v;
  cv::minMaxLoc(r.disparity, &min_v, &max_v);
  EXPECT_GE(min_v, 9.0);
  EXPECT_LE(max_v, 11.0);
}

TEST(PatchMatch, ScratchBuffersDoNotLeakBetweenFrames) {
  // The same object on two different scenes, then the first again: identical to a fresh object.
  const PlaneScene a = PlaneScene::make(120, 64, 0.02, 0.0, 8.0, 31);
  const PlaneScene b = PlaneScene::make(96, 48, 0.0, 0.03, 14.0, 32);
  lsf::PatchMatchStereo reused(stereoOnly());
  const auto first = reused.compute({a.left, cv::Mat1f(), {}}, {a.right, cv::Mat1f(), {}});
  reused.compute({b.left, cv::Mat1f(), {}}, {b.right, cv::Mat1f(), {}});
  const auto again = reused.compute({a.left, cv::Mat1f(), {}}, {a.right, cv::Mat1f(), {}});
  EXPECT_EQ(cv::norm(first.disparity, again.disparity, cv::NORM_INF), 0.0);
}

TEST(PatchMatch, DeterministicForSeedAndThreadCount) {
  const PlaneScene s = PlaneScene::make(120, 64, 0.03, 0.0, 9.0, 21);
  for (const bool live : {false, true}) {  // the default and the live preset's search
    auto p = stereoOnly();
    if (live) {
      p.search_scale = 2;
      p.intermediate_refine = false;
    }
    p.num_threads = 1;
    const auto a =
        lsf::PatchMatchStereo(p).compute({s.left, cv::Mat1f(), {}}, {s.right, cv::Mat1f(), {}});
    p.num_threads = 2;
    const auto b =
        lsf::PatchMatchStereo(p).compute({s.left, cv::Mat1f(), {}}, {s.right, cv::Mat1f(), {}});
    EXPECT_EQ(cv::norm(a.disparity, b.disparity, cv::NORM_INF), 0.0) << "live " << live;
  }
}

TEST(PatchMatch, SearchScale2EndsWithTheSubpixelStepAtHalfSize) {
  // The finest level that searches polishes its planes with the sub-pixel step: full size, or
  // with search_scale 2 (the live preset) the 1/2-size level, whose planes full size up-samples.
  lsf::PatchMatchParams p;
  EXPECT_FALSE(lsf::patchmatch::coarseParams(p).fine_subpixel);  // full size searches
  p.search_scale = 2;
  const lsf::PatchMatchParams half = lsf::patchmatch::coarseParams(p);
  EXPECT_TRUE(half.fine_subpixel);
  EXPECT_FALSE(lsf::patchmatch::coarseParams(half).fine_subpixel);  // the 1/4 level refines
  p.fine_subpixel = false;
  EXPECT_FALSE(lsf::patchmatch::coarseParams(p).fine_subpixel);
  // Stereo only, slanted planes: the step makes the up-sampled planes more precise, in sum over
  // 12 scenes (0.88x the error without it; single scenes 0.65-1.08x).
  double error[2] = {0.0, 0.0};
  for (const uint64_t seed : {1, 2, 3, 4, 5, 6}) {
    for (const double c : {6.3, 9.1}) {
      const PlaneScene s = PlaneScene::make(128, 64, 0.05, 0.02, c, seed);
      for (const bool subpixel : {false, true}) {
        lsf::PatchMatchParams q = stereoOnly();
        q.search_scale = 2;
        q.max_disparity = 16;
        q.fine_subpixel = subpixel;
        q.num_threads = 1;
        const auto r =
            lsf::PatchMatchStereo(q).compute({s.left, cv::Mat1f(), {}}, {s.right, cv::Mat1f(), {}});
        error[subpixel] += meanError(r.disparity, s, 12);
      }
    }
  }
  EXPECT_LT(error[1], 0.93 * error[0]) << error[1] << " against " << error[0];
}

TEST(PatchMatch, FullSearchPixelsSearchesASmallImageInFull) {
  lsf::PatchMatchParams p;
  p.search_scale = 2;  // the live preset's cuts
  p.intermediate_refine = false;
  EXPECT_EQ(p.forImage(450, 375).search_scale, 2);  // 0: never
  p.full_search_pixels = 200000;                    // the live preset
  for (const cv::Size& size : {cv::Size(450, 375), cv::Size(500, 400), cv::Size(400, 500)}) {
    const lsf::PatchMatchParams q = p.forImage(size.width, size.height);
    EXPECT_EQ(q.search_scale, 1) << size;  // Middlebury's quarter size; exactly the budget
    EXPECT_TRUE(q.intermediate_refine) << size;
    EXPECT_EQ(q.full_search_pixels, p.full_search_pixels);  // the rest as set
  }
  for (const cv::Size& size : {cv::Size(501, 400), cv::Size(1242, 375), cv::Size(1280, 720)}) {
    const lsf::PatchMatchParams q = p.forImage(size.width, size.height);
    EXPECT_EQ(q.search_scale, 2) << size;  // one pixel more; KITTI; the rig
    EXPECT_FALSE(q.intermediate_refine) << size;
  }
  p.full_search_pixels = -1;
  EXPECT_THROW(p.validate(), std::invalid_argument);

  // The search is the full one, bit for bit, up to the budget; params() stays as set.
  const PlaneScene s = PlaneScene::make(96, 48, 0.04, 0.0, 7.0, 5);
  const lsf::ViewInput left{s.left, cv::Mat1f(), {}}, right{s.right, cv::Mat1f(), {}};
  lsf::PatchMatchParams q = stereoOnly();
  q.max_disparity = 16;
  q.num_threads = 1;
  const cv::Mat1f full = lsf::PatchMatchStereo(q).compute(left, right).disparity;
  q.search_scale = 2;
  q.intermediate_refine = false;
  const cv::Mat1f cut = lsf::PatchMatchStereo(q).compute(left, right).disparity;
  ASSERT_GT(cv::norm(full, cut, cv::NORM_INF), 0.0);  // the two searches differ here
  for (const int budget : {96 * 48, 96 * 48 - 1}) {
    q.full_search_pixels = budget;
    lsf::PatchMatchStereo solver(q);
    const cv::Mat1f d = solver.compute(left, right).disparity;
    EXPECT_EQ(cv::norm(d, budget == 96 * 48 ? full : cut, cv::NORM_INF), 0.0) << budget;
    EXPECT_EQ(solver.params().search_scale, 2);
  }
}

TEST(PatchMatch, RejectsBadInput) {
  lsf::PatchMatchParams p;
  p.alpha = 0.5;  // sum != 1
  EXPECT_THROW(p.validate(), std::invalid_argument);
  lsf::PatchMatchParams q;
  q.right_iterations = 0;
  EXPECT_THROW(q.validate(), std::invalid_argument);
  q.right_iterations = -2;
  EXPECT_THROW(q.validate(), std::invalid_argument);
  // unbounded_scale is a level's reduction factor: 1, 2 or 4 with two levels of 2.
  lsf::PatchMatchParams u;
  for (const int scale : {1, 2, 4}) {
    u.unbounded_scale = scale;
    EXPECT_NO_THROW(u.validate()) << scale;
  }
  for (const int scale : {0, 3, 8}) {
    u.unbounded_scale = scale;
    try {
      u.validate();
      ADD_FAILURE() << "unbounded_scale " << scale << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("unbounded_scale"), std::string::npos) << e.what();
    }
  }
  u.unbounded_scale = 2;
  u.coarse_scale = 1;  // no coarse start: no level but full size
  EXPECT_THROW(u.validate(), std::invalid_argument);
  lsf::PatchMatchParams search;
  search.search_scale = 3;
  EXPECT_THROW(search.validate(), std::invalid_argument);
  search.search_scale = 4;
  EXPECT_NO_THROW(search.validate());
  lsf::PatchMatchStereo pm;
  cv::Mat a(10, 20, CV_8UC3), b(10, 21, CV_8UC3);
  EXPECT_THROW(pm.compute({a, cv::Mat1f(), {}}, {b, cv::Mat1f(), {}}), std::invalid_argument);
  cv::Mat f(10, 20, CV_32FC3);
  EXPECT_THROW(pm.compute({f, cv::Mat1f(), {}}, {f, cv::Mat1f(), {}}), std::invalid_argument);
}
