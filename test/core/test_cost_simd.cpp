// Which SIMD path the matching cost runs (the widest the CPU has, an unsupported one refused) and
// whole PatchMatch runs on every path giving the baseline's result. The kernels themselves:
// test_cost_simd_kernels.cpp; LSF_SIMD in the tools: test/io/test_simd_env.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "cost_simd_util.h"
#include "lidar_stereo_fusion/core/patchmatch.h"
#include "lidar_stereo_fusion/core/patchmatch/simd.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "test_scenes.h"

namespace lsf = lidar_stereo_fusion;

using lidar_stereo_fusion::test::widePaths;

namespace {

/// Fraction of pixels where two disparity maps differ by more than 1e-3 px.
double differingFraction(const cv::Mat1f& a, const cv::Mat1f& b) {
  int n = 0;
  for (int y = 0; y < a.rows; ++y) {
    for (int x = 0; x < a.cols; ++x) n += std::abs(a(y, x) - b(y, x)) > 1e-3f;
  }
  return static_cast<double>(n) / a.total();
}

}  // namespace

TEST(CostSimd, DefaultsToTheWidestPath) {
  const lsf::SimdPath widest = lsf::widestSimdPath();
  const std::string level = lsf::simdPathName(widest);
  EXPECT_TRUE(level == "avx512" || level == "avx2" || level == "baseline") << level;
  EXPECT_TRUE(lsf::simdPathSupported(widest)) << level;
  EXPECT_TRUE(lsf::simdPathSupported(lsf::SimdPath::kBaseline));
  EXPECT_EQ(lsf::PatchMatchParams().simd_path, widest);
  if (!lsf::cpuHasAvx2Fma()) {
    EXPECT_EQ(level, "baseline");
    EXPECT_FALSE(lsf::cpuHasAvx512()) << "the AVX-512 path needs the AVX2 one's window";
  }
  EXPECT_EQ(level, lsf::cpuHasAvx512() ? "avx512" : (lsf::cpuHasAvx2Fma() ? "avx2" : "baseline"));
  for (const lsf::SimdPath path :
       {lsf::SimdPath::kBaseline, lsf::SimdPath::kAvx2, lsf::SimdPath::kAvx512}) {
    lsf::SimdPath parsed = lsf::SimdPath::kBaseline;
    EXPECT_TRUE(lsf::parseSimdPath(lsf::simdPathName(path), parsed));
    EXPECT_EQ(parsed, path);
    EXPECT_EQ(lsf::capSimdPath(path), lsf::simdPathSupported(path) ? path : widest);
  }
  lsf::SimdPath untouched = lsf::SimdPath::kAvx2;
  EXPECT_FALSE(lsf::parseSimdPath("sse2", untouched));
  EXPECT_EQ(untouched, lsf::SimdPath::kAvx2);
  std::printf("[          ] widest path %s; AVX2 + FMA %s, AVX-512 %s\n", level.c_str(),
              lsf::cpuHasAvx2Fma() ? "yes" : "no", lsf::cpuHasAvx512() ? "yes" : "no");
}

TEST(CostSimd, AnUnsupportedPathIsRejected) {
  for (const lsf::SimdPath path : {lsf::SimdPath::kAvx2, lsf::SimdPath::kAvx512}) {
    lsf::PatchMatchParams p;
    p.simd_path = path;
    if (lsf::simdPathSupported(path)) {
      EXPECT_NO_THROW(p.validate());
      EXPECT_NO_THROW(lsf::PatchMatchStereo{p});
    } else {
      EXPECT_THROW(p.validate(), std::invalid_argument);
      EXPECT_THROW(lsf::PatchMatchStereo{p}, std::invalid_argument);
    }
  }
}

TEST(CostSimd, PatchMatchSameOnBothPaths) {
  SKIP_WITHOUT_AVX2();
  // A slanted textured plane with a LiDAR-like prior: rows every 4th line, holes, mixed confidence.
  const auto s = lsf::test::PlaneScene::make(240, 120, 0.06, 0.03, 12.0, 41);
  cv::Mat1f prior(120, 240, 0.f), confidence(120, 240, 0.f);
  for (int y = 0; y < 120; y += 4) {
    for (int x = 30; x < 240; ++x) {
      prior(y, x) = static_cast<float>(s.disparity(x, y));
      confidence(y, x) = (x % 7) / 6.f;
    }
  }
  for (const int variant : {0, 1, 2}) {  // confidence-weighted, the paper's cost, the live preset
    const bool weighted = variant != 1;
    lsf::PatchMatchParams p;
    p.confidence_weighting = weighted;
    if (variant == 2) {
      p.search_scale = 2;
      p.intermediate_refine = false;
    }
    p.num_threads = 2;
    const lsf::ViewInput left(s.left, prior, {}, confidence), right(s.right, cv::Mat1f(), {});
    // One matcher per path, alive side by side in one process: each keeps its own path.
    lsf::PatchMatchParams base_params = p;
    base_params.simd_path = lsf::SimdPath::kBaseline;
    lsf::PatchMatchStereo base_matcher(base_params);
    const auto base = base_matcher.compute(left, right);
    for (const lsf::SimdPath wide : widePaths()) {
      lsf::PatchMatchParams fast_params = p;
      fast_params.simd_path = wide;
      lsf::PatchMatchStereo fast_matcher(fast_params);
      const auto fast = fast_matcher.compute(left, right);
      const auto again = base_matcher.compute(left, right);  // after the other path ran
      EXPECT_EQ(cv::norm(again.disparity, base.disparity, cv::NORM_INF), 0.0);
      const char* level = lsf::simdPathName(wide);
      const double differ = differingFraction(fast.disparity, base.disparity);
      std::printf("[          ] %s, variant %d: %.4f %% of pixels differ by > 1e-3 px\n", level,
                  variant, 100 * differ);
      EXPECT_LE(differ, 1e-3) << level << " variant " << variant;
      EXPECT_EQ(cv::norm(fast.disparity, base.disparity, cv::NORM_INF), 0.0)
          << level << " variant " << variant
          << ": the kernels are bit-identical, so should be the results";
    }
  }
}
