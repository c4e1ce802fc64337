// Stage 2 in the pipeline (BI*'s prior, bounds and confidence in one row pass over one column
// index, the index kept through Algorithm 1) gives bit for bit what the public steps give one by
// one, each on its own index.
#include <vector>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/core/prior_confidence.h"
#include "lidar_stereo_fusion/core/upsampling.h"
#include "test_scenes.h"

namespace lsf = lidar_stereo_fusion;

namespace {

constexpr int kWidth = 40, kHeight = 32;

/// Rings on rows 2, 5, 9, 12, 20 and 29 of every column, with depth edges, slopes, gaps that Eq. 3
/// bridges and one it does not (20 -> 29 with max_interp_rows 8), and background points on row 9
/// between foreground lines in columns 10-19, which Algorithm 1 removes.
lsf::SparseDisparity scene() {
  lsf::SparseDisparity s;
  s.disparity = cv::Mat1f::zeros(kHeight, kWidth);
  s.ring = cv::Mat1s(kHeight, kWidth, short(-1));
  const int rows[] = {2, 5, 9, 12, 20, 29};
  for (int r = 0; r < 6; ++r) {
    for (int x = 0; x < kWidth; ++x) {
      float d = 10.f + 0.25f * r + 0.05f * x;                 // a slanted surface
      if (x >= 10 && x < 20 && (r == 1 || r == 3)) d = 30.f;  // foreground around row 9
      if (x >= 10 && x < 20 && r == 2) d = 8.f;               // background between: occluded
      if (x >= 25 && r == 4) d = 18.f + (x % 3);              // an edge between rows 12 and 20
      if (x % 7 == 3 && r == 5) continue;                     // gaps along the last ring
      s.disparity(rows[r], x) = d;
      s.ring(rows[r], x) = static_cast<short>(r);
    }
  }
  return s;
}

int differing(const cv::Mat1f& a, const cv::Mat1f& b) {
  return a.size() == b.size() ? cv::countNonZero(a != b) : -1;
}

}  // namespace

TEST(StageTwoOnePass, PipelinePriorAndConfidenceEqualThePublicStepsBitForBit) {
  lsf::FusionParams params;
  params.method = lsf::Method::kLidarBI;  // the prior as it is (no hole fill)
  params.bi.max_interp_rows = 8;
  params.bi.max_gap_px = 1;  // keep the ring gaps of scene()
  const cv::Mat image(kHeight, kWidth, CV_8UC3, cv::Scalar(90, 90, 90));
  const lsf::StereoCamera camera = lsf::test::centredCamera(kWidth, kHeight, 100.0);
  lsf::FusionPipeline pipeline(params);
  const lsf::FusionResult r =
      pipeline.processSparse(image, image, scene(), lsf::SparseDisparity(), camera);

  // The public steps, each building its own column index from the lines.
  lsf::ScanLines lines = lsf::completeScanLines(scene(), params.bi);
  std::vector<cv::Point> removed;
  const int count = lsf::removeOccludedPoints(lines, image, params.bi, &removed);
  const cv::Mat1f prior = lsf::interpolateBetweenScanLines(lines, params.bi);
  const cv::Mat1f confidence = lsf::priorConfidence(lines, prior, removed, params.confidence);

  EXPECT_EQ(count, 10);  // row 9, columns 10-19
  EXPECT_EQ(r.stats.points_removed, count);
  EXPECT_EQ(differing(r.prior, prior), 0);
  EXPECT_EQ(differing(r.confidence, confidence), 0);
  // The scene reaches every branch: unbridged rows (21-28) stay 0, removals and edges lower the
  // confidence, agreeing lines keep it high.
  EXPECT_EQ(prior(24, 0), 0.f);
  EXPECT_EQ(confidence(24, 0), 0.f);
  EXPECT_GT(prior(16, 0), 0.f);
  EXPECT_LT(confidence(10, 15), confidence(10, 5));
  EXPECT_LT(confidence(16, 30), confidence(16, 5));
  EXPECT_GT(confidence(16, 5), 0.5f);

  // upsampleBI, which keeps its index through Algorithm 1 as well, agrees with the steps too.
  std::vector<cv::Point> removed_bi;
  int count_bi = 0;
  lsf::ScanLines lines_bi;
  const cv::Mat1f prior_bi =
      lsf::upsampleBI(scene(), image, params.bi, &count_bi, &lines_bi, &removed_bi);
  EXPECT_EQ(count_bi, count);
  EXPECT_EQ(removed_bi, removed);
  EXPECT_EQ(differing(prior_bi, prior), 0);
  EXPECT_EQ(differing(lines_bi.disparity, lines.disparity), 0);
}
