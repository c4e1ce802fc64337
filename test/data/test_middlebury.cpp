// Middlebury 2003 cones and teddy (quarter size) with a pseudo-LiDAR: 64 evenly spaced rows of the
// ground truth, every pixel of those rows where it exists, rows as rings 0..63. The fused method
// (BI* up-sampling + guided PatchMatch) must beat LiDAR-only BI* interpolation and plain PMS on
// bad-2 and MAE over all ground-truth pixels (missing estimates count as errors of the full
// disparity).
//
// The stages are composed here from upsampling.h and patchmatch.h the way FusionPipeline::process
// composes them (BI* in both views, scan-line bounds, PatchMatch), because the pipeline takes a
// point cloud and this input is a disparity map.
#include <iostream>

#include <gtest/gtest.h>

#include "data/data_guard.h"
#include "lidar_stereo_fusion/core/metrics.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/io/middlebury.h"
#include "lidar_stereo_fusion/io/report.h"

namespace lidar_stereo_fusion {
namespace {

constexpr int kRings = 64;

/// Default parameters with the image-wide disparity range of the quarter-size scenes (GT <= 64).
FusionParams middleburyParams() {
  FusionParams params;
  params.patchmatch.min_disparity = 1.0;
  params.patchmatch.max_disparity = 64.0;
  return params;
}

struct ViewPrior {
  cv::Mat1f prior;
  ScanLineBounds bounds;
};

ViewPrior upsampleView(const SparseDisparity& sparse, const cv::Mat& image,
                       const FusionParams& params) {
  ViewPrior view;
  ScanLines lines;
  view.prior = upsampleBI(sparse, image, params.bi, nullptr, &lines);
  view.bounds = computeScanLineBounds(lines, params.patchmatch.bound_margin);
  return view;
}

struct SceneResult {
  DisparityMetrics lidar_bi, fused_bi, pms;
};

SceneResult runScene(const std::string& name) {
  const MiddleburyScene scene = readMiddleburyScene(test::dataPath("middlebury/" + name));
  const FusionParams params = middleburyParams();
  const SparseDisparity left_sparse = sampleRowsAsScanLines(scene.disparity, kRings);
  const SparseDisparity right_sparse = shiftToRightView(left_sparse);
  const ViewPrior left = upsampleView(left_sparse, scene.left, params);
  const ViewPrior right = upsampleView(right_sparse, scene.right, params);

  PatchMatchStereo fused(params.patchmatch);
  const cv::Mat1f fused_disparity =
      fused.compute({scene.left, left.prior, left.bounds}, {scene.right, right.prior, right.bounds})
          .disparity;
  PatchMatchStereo plain(FusionParams::plainPmsParams(params.patchmatch));
  const cv::Mat1f pms_disparity = plain
                                      .compute({scene.left, cv::Mat1f(), ScanLineBounds(), cv::Mat1f()},
                                               {scene.right, cv::Mat1f(), ScanLineBounds(), cv::Mat1f()})
                                      .disparity;

  SceneResult result;
  result.lidar_bi = evaluateDisparity(left.prior, scene.disparity);
  result.fused_bi = evaluateDisparity(fused_disparity, scene.disparity);
  result.pms = evaluateDisparity(pms_disparity, scene.disparity);
  std::cout << "Middlebury " << name << " (quarter size, " << kRings
            << " ground-truth rows as pseudo-LiDAR, " << left_sparse.points_in_image
            << " samples; seed " << params.patchmatch.seed << "):\n"
            << formatDisparityTable({{"lidar_bi", result.lidar_bi},
                                     {"fused_bi", result.fused_bi},
                                     {"pms", result.pms}});
  return result;
}

void expectFusedBeatsBaselines(const std::string& name) {
  const SceneResult r = runScene(name);
  const uint64_t seed = middleburyParams().patchmatch.seed;
  EXPECT_LT(r.fused_bi.bad2, r.lidar_bi.bad2) << name << ", seed " << seed;
  EXPECT_LT(r.fused_bi.mae_px, r.lidar_bi.mae_px) << name << ", seed " << seed;
  EXPECT_LT(r.fused_bi.bad2, r.pms.bad2) << name << ", seed " << seed;
  EXPECT_LT(r.fused_bi.mae_px, r.pms.mae_px) << name << ", seed " << seed;
}

TEST(Middlebury, PseudoLidarRowsAreExactGroundTruthSamples) {
  LSF_REQUIRE_DATA("middlebury/cones");
  const MiddleburyScene scene = readMiddleburyScene(test::dataPath("middlebury/cones"));
  ASSERT_EQ(scene.left.size(), cv::Size(450, 375));
  const SparseDisparity sparse = sampleRowsAsScanLines(scene.disparity, kRings);
  int rows_with_samples = 0;
  for (int y = 0; y < sparse.disparity.rows; ++y) {
    int samples = 0;
    for (int x = 0; x < sparse.disparity.cols; ++x) {
      if (sparse.disparity(y, x) > 0) {
        ++samples;
        ASSERT_EQ(sparse.disparity(y, x), scene.disparity(y, x));
        ASSERT_EQ(sparse.ring(y, x), rows_with_samples);
      }
    }
    rows_with_samples += samples > 0;
  }
  EXPECT_EQ(rows_with_samples, kRings);
}

TEST(Middlebury, FusedBeatsLidarOnlyAndPlainPmsOnCones) {
  LSF_REQUIRE_DATA("middlebury/cones");
  expectFusedBeatsBaselines("cones");
}

TEST(Middlebury, FusedBeatsLidarOnlyAndPlainPmsOnTeddy) {
  LSF_REQUIRE_DATA("middlebury/teddy");
  expectFusedBeatsBaselines("teddy");
}

}  // namespace
}  // namespace lidar_stereo_fusion
