// RateGovernor (ros/rate_governor.h): the steps of search effort and when it takes them.
#include <gtest/gtest.h>

#include "lidar_stereo_fusion/ros/rate_governor.h"

namespace lsf = lidar_stereo_fusion;

namespace {

/// The live preset's search (config/live.yaml): two coarse levels of factor 2, pixels without
/// bounds searched down to 1/2 size, two sweeps at 1/4, the 1/2 level only propagating.
lsf::FusionParams livePreset() {
  lsf::FusionParams f;  // method fused_bi
  lsf::PatchMatchParams& p = f.patchmatch;
  p.coarse_scale = 2;
  p.coarse_levels = 2;
  p.search_scale = 2;
  p.unbounded_scale = 1;  // config/live.yaml keeps the default: search_scale 2 bounds it
  p.iterations = 2;
  p.intermediate_refine = false;
  return f;
}

/// Feeds `n` frames with the input `period` [s], each followed by `dropped` drops every `every`-th
/// frame; returns how many calls changed the step.
int feed(lsf::RateGovernor& g, int n, double period, double busy_ms, int every,
         unsigned dropped = 1) {
  int changes = 0;
  for (int i = 0; i < n; ++i) {
    const bool late = every > 0 && i % every == every - 1;
    changes += g.observe(late ? dropped : 0u, period, busy_ms) ? 1 : 0;
  }
  return changes;
}

}  // namespace

TEST(RateGovernor, StepsAlternateOneMoreLevelAndACoarserSearchWithoutBounds) {
  const auto live = lsf::effortSteps(livePreset());
  ASSERT_EQ(live.size(), 4u);
  const int levels[] = {2, 3, 2, 3}, coarsest[] = {4, 8, 4, 8};
  const int unbounded[] = {2, 2, 4, 4};
  for (size_t i = 0; i < live.size(); ++i) {
    EXPECT_EQ(live[i].coarse_levels, levels[i]) << i;
    EXPECT_EQ(live[i].coarsest_scale, coarsest[i]) << i;
    EXPECT_EQ(live[i].unbounded_scale, unbounded[i]) << i;  // never coarser than base's coarsest
    EXPECT_EQ(live[i].iterations, 2) << i;  // one sweep only where no level can be added
  }
  EXPECT_EQ(live[0].describe(),
            "search from 1/4 size, pixels without scan-line bounds searched down to 1/2 size, 2 "
            "sweeps at the coarsest level");
  EXPECT_EQ(live[3].describe(),
            "search from 1/8 size, pixels without scan-line bounds searched down to 1/4 size, 2 "
            "sweeps at the coarsest level");

  lsf::FusionParams propagating = livePreset();  // every level searches, the 1/2 level propagates
  propagating.patchmatch.search_scale = 1;
  propagating.patchmatch.unbounded_scale = 1;
  EXPECT_EQ(lsf::effortSteps(propagating).size(), 6u);  // 1, 2, 4, each then one more level

  lsf::FusionParams deepest = propagating;  // already at the most coarse levels: none is added
  deepest.patchmatch.coarse_levels = lsf::PatchMatchParams::kMaxCoarseLevels;
  const auto deep = lsf::effortSteps(deepest);
  ASSERT_EQ(deep.size(), 6u);  // 1, 2, 4, 8, 16, then one sweep
  for (const lsf::EffortStep& s : deep) EXPECT_EQ(s.coarse_levels, 4);
  EXPECT_EQ(deep[4].unbounded_scale, 16);
  for (const lsf::EffortStep& s : deep) EXPECT_TRUE(s.refine_between);  // nothing to give up

  lsf::FusionParams flat;  // no coarse level: nothing to give up
  flat.patchmatch.coarse_levels = 0;
  flat.patchmatch.coarse_scale = 1;
  EXPECT_EQ(lsf::effortSteps(flat).size(), 1u);

  // Not fused (stereo alone, LiDAR alone): no scan-line bounds to search by.
  for (lsf::Method m : {lsf::Method::kPlainPMS, lsf::Method::kLidarBI, lsf::Method::kLidarBF}) {
    lsf::FusionParams other = livePreset();
    other.method = m;
    EXPECT_EQ(lsf::effortSteps(other).size(), 1u) << lsf::methodName(m);
  }
}

TEST(RateGovernor, ABaseWhoseLevelsBetweenRefineGivesThatUpFirst) {
  const lsf::FusionParams fusion;  // the default preset: the 1/2 level's right view refines
  ASSERT_TRUE(fusion.patchmatch.intermediate_refine);
  const auto steps = lsf::effortSteps(fusion);
  ASSERT_EQ(steps.size(), 5u);  // as configured, no refinement between, 2, 4, then one more level
  const int levels[] = {2, 2, 2, 2, 3}, coarsest[] = {4, 4, 4, 4, 8};
  const int unbounded[] = {1, 1, 2, 4, 4};
  for (size_t i = 0; i < steps.size(); ++i) {
    EXPECT_EQ(steps[i].coarse_levels, levels[i]) << i;
    EXPECT_EQ(steps[i].coarsest_scale, coarsest[i]) << i;
    EXPECT_EQ(steps[i].unbounded_scale, unbounded[i]) << i;
    EXPECT_EQ(steps[i].iterations, 2) << i;
    EXPECT_EQ(steps[i].refine_between, i == 0) << i;
  }
  EXPECT_EQ(steps[1].describe(),
            "search from 1/4 size, pixels without scan-line bounds searched down to full size, 2 "
            "sweeps at the coarsest level, the right view not refined between the coarsest level "
            "and full size");

  lsf::RateGovernor g(fusion);
  EXPECT_TRUE(g.params().patchmatch.intermediate_refine);
  ASSERT_EQ(feed(g, 10, 0.1, 130.0, 5), 1);
  EXPECT_EQ(g.step(), 1);
  const lsf::PatchMatchParams p = g.params().patchmatch;
  EXPECT_FALSE(p.intermediate_refine);
  EXPECT_EQ(p.coarse_levels, 2);
  EXPECT_EQ(p.unbounded_scale, 1);
  EXPECT_EQ(p.search_scale, 1);  // the rest as configured
  EXPECT_NO_THROW(p.validate());

  lsf::FusionParams deepest = fusion;  // no level can be added: one sweep last
  deepest.patchmatch.coarse_levels = lsf::PatchMatchParams::kMaxCoarseLevels;
  const auto deep = lsf::effortSteps(deepest);
  ASSERT_EQ(deep.size(), 7u);  // as configured, then 1, 2, 4, 8, 16 without, then one sweep
  EXPECT_EQ(deep[5].unbounded_scale, 16);
  EXPECT_EQ(deep[6].iterations, 1);
  for (const lsf::EffortStep& s : deep) EXPECT_EQ(s.coarse_levels, 4);

  lsf::FusionParams one_level = fusion;  // no level between the coarsest and full size
  one_level.patchmatch.coarse_levels = 1;
  for (const lsf::EffortStep& s : lsf::effortSteps(one_level)) EXPECT_TRUE(s.refine_between);
}

TEST(RateGovernor, KeepsTheSearchWhileNoSetIsDropped) {
  lsf::RateGovernor g(livePreset());
  EXPECT_EQ(feed(g, 500, 0.1, 95.0, 0), 0);
  EXPECT_EQ(g.step(), 0);
  EXPECT_EQ(g.params().patchmatch.unbounded_scale,
            1);  // the first step is the configured search itself
}

TEST(RateGovernor, OneDropInTenFramesIsNoReasonToStep) {
  lsf::RateGovernor g(livePreset());
  EXPECT_EQ(feed(g, 300, 0.1, 90.0, 10), 0);  // exactly one late frame in every window
  EXPECT_EQ(g.step(), 0);
}

TEST(RateGovernor, StepsDownWhenTwoOfTenFramesAreFollowedByDrops) {
  lsf::RateGovernor g(livePreset());
  // Every 5th frame late: the 10th frame completes the first window with two late frames.
  int changes = 0, at = -1;
  for (int i = 0; i < 10; ++i) {
    const bool late = i % 5 == 4;
    if (g.observe(late ? 1u : 0u, 0.1, 130.0)) {
      ++changes;
      at = i;
    }
  }
  EXPECT_EQ(changes, 1);
  EXPECT_EQ(at, 9);
  EXPECT_EQ(g.step(), 1);
  EXPECT_EQ(g.params().patchmatch.coarse_levels, 3);
  EXPECT_EQ(g.params().patchmatch.unbounded_scale, 2);
  EXPECT_EQ(g.params().patchmatch.iterations, 2);
  EXPECT_EQ(g.params().patchmatch.search_scale, 2);  // the rest as configured
  EXPECT_NO_THROW(g.params().validate());
  EXPECT_EQ(g.reason(),
            "2 of the last 10 frames were followed by dropped input sets (frames take 130 ms, "
            "median, input every 100 ms)");
  // Still late: one step per full window down to the last, then no further step exists.
  EXPECT_EQ(feed(g, 10, 0.1, 110.0, 5), 1);
  EXPECT_EQ(g.step(), 2);
  EXPECT_EQ(g.params().patchmatch.coarse_levels, 2);  // the configured levels again
  EXPECT_EQ(g.params().patchmatch.unbounded_scale, 4);
  EXPECT_EQ(feed(g, 10, 0.1, 108.0, 5), 1);
  EXPECT_EQ(g.step(), 3);
  EXPECT_EQ(g.params().patchmatch.coarse_levels, 3);
  EXPECT_EQ(g.params().patchmatch.unbounded_scale, 4);
  EXPECT_EQ(g.params().patchmatch.iterations, 2);
  EXPECT_NO_THROW(g.params().validate());
  EXPECT_EQ(feed(g, 50, 0.1, 105.0, 5), 0);
  EXPECT_EQ(g.step(), 3);
}

TEST(RateGovernor, StepsBackUpOnlyWhenTheFinerStepIsPredictedToFit) {
  lsf::RateGovernor g(livePreset());
  ASSERT_EQ(feed(g, 10, 0.1, 130.0, 5), 1);  // left step 0 at 130 ms
  // Step 1 takes 97 ms: step 0 is predicted at 130 ms, more than 0.8 x 100: it stays.
  EXPECT_EQ(feed(g, 300, 0.1, 97.0, 0), 0);
  EXPECT_EQ(g.step(), 1);
  // The host calms down: step 1 now takes 48.5 ms, so step 0 is predicted at 65 ms (<= 80 ms);
  // the median of the window follows after 6 frames.
  int changes = 0, at = -1;
  for (int i = 0; i < 20 && changes == 0; ++i) {
    if (g.observe(0u, 0.1, 48.5)) {
      ++changes;
      at = i;
    }
  }
  EXPECT_EQ(changes, 1);
  EXPECT_EQ(at, 5);
  EXPECT_EQ(g.step(), 0);
  EXPECT_EQ(g.reason(),
            "no input set dropped in 306 frames (frames take 49 ms, median; the finer step is "
            "predicted at 65 ms, input every 100 ms)");
}

TEST(RateGovernor, ARebaseStartsFromTheNewSearch) {
  lsf::RateGovernor g(livePreset());
  ASSERT_EQ(feed(g, 10, 0.1, 130.0, 5), 1);
  lsf::FusionParams changed = livePreset();
  changed.patchmatch.iterations = 3;
  g.rebase(changed);
  EXPECT_EQ(g.step(), 0);
  EXPECT_EQ(g.params().patchmatch.iterations, 3);
  EXPECT_EQ(g.steps(), 4);
}

TEST(RateGovernor, AnUnknownPeriodStepsDownButNeverUp) {
  // The period is InputGate's (FreshWait: the median interval of the sets; 0 until three are
  // known, and after a time jump back).
  lsf::RateGovernor g(livePreset());
  ASSERT_EQ(feed(g, 10, 0.0, 130.0, 5), 1);
  EXPECT_EQ(g.reason(),
            "2 of the last 10 frames were followed by dropped input sets (frames take 130 ms, "
            "median)");
  EXPECT_EQ(feed(g, 10, 0.0, 97.0, 0), 0);   // step 1's first window: 97 ms
  EXPECT_EQ(feed(g, 300, 0.0, 20.0, 0), 0);  // step 0 predicted at 27 ms, but no period known
  EXPECT_EQ(g.step(), 1);
  EXPECT_EQ(feed(g, 1, 0.1, 20.0, 0), 1);  // a period again: 27 <= 80 ms, back up
  EXPECT_EQ(g.step(), 0);
}
