// Ring hold-out on the real KITTI drive: feed the even rings, score against the odd rings' depth
// (KITTI devkit metrics, missing estimates count as depth 0). Fused BI* must beat LiDAR-only BI*
// and plain PMS on mean MAE and RMSE; the table of all five methods is printed.
//
// Time budget: the fused and LiDAR-only methods run on all 11 frames; plain PMS (35x35 windows,
// unbounded search: ~15 s per 1242x375 frame on 2 cores) runs on frames 0, 25 and 50 only and is
// compared with fused BI* on those same frames.
#include <iostream>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "data/data_guard.h"
#include "lidar_stereo_fusion/core/metrics.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/io/holdout.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/report.h"

namespace lidar_stereo_fusion {
namespace {

const char* const kDrive = "kitti_raw/2011_09_26/2011_09_26_drive_0009_sync";
const std::set<std::string> kPmsFrames = {"0000000000", "0000000025", "0000000050"};

struct MethodScores {
  std::vector<DepthMetrics> all;         ///< every frame the method ran on
  std::vector<DepthMetrics> pms_frames;  ///< the frames plain PMS ran on
  std::vector<FrameStats> stats;
};

TEST(KittiHoldout, FusedBIBeatsLidarOnlyAndPlainPmsOnTheOddRings) {
  LSF_REQUIRE_DATA(kDrive);
  const std::string drive = test::dataPath(kDrive);
  const kitti::Calibration calib = kitti::readCalibration(kitti::calibrationDirOf(drive));
  const std::vector<kitti::Frame> frames = kitti::listFrames(drive);
  ASSERT_EQ(frames.size(), 11u);

  const std::vector<Method> methods = {Method::kFusedBI, Method::kFusedBF, Method::kPlainPMS,
                                       Method::kLidarBI, Method::kLidarBF};
  std::map<Method, FusionPipeline> pipelines;
  for (Method m : methods) {
    FusionParams params;
    params.method = m;
    pipelines.emplace(m, FusionPipeline(params));
  }
  const uint64_t seed = FusionParams().patchmatch.seed;

  std::map<Method, MethodScores> scores;
  for (const kitti::Frame& frame : frames) {
    const kitti::FrameData data = kitti::loadFrame(frame, calib.camera);
    const HoldoutCase holdout =
        makeRingHoldout(data.cloud, calib.T_cam_velo, calib.camera, FusionParams().projection);
    const FusionInput input{data.left, data.right, holdout.fed, calib.T_cam_velo, calib.camera};
    const bool pms_frame = kPmsFrames.count(frame.name) > 0;
    for (Method m : methods) {
      if (m == Method::kPlainPMS && !pms_frame) continue;
      const FusionResult result = pipelines.at(m).process(input);
      const DepthMetrics metrics =
          evaluateDepth(result.depth, holdout.reference_depth, calib.camera);
      scores[m].all.push_back(metrics);
      if (pms_frame) scores[m].pms_frames.push_back(metrics);
      scores[m].stats.push_back(result.stats);
    }
  }

  std::vector<DepthRow> rows;
  for (Method m : methods) {
    const std::string frames_note = " (" + std::to_string(scores[m].all.size()) + " frames)";
    rows.push_back({methodName(m) + frames_note, averageMetrics(scores[m].all)});
  }
  rows.push_back(
      {"fused_bi on the PMS frames (3)", averageMetrics(scores[Method::kFusedBI].pms_frames)});
  std::cout << "KITTI ring hold-out (even rings in, odd rings scored), drive 0009, seed " << seed
            << ":\n"
            << formatDepthTable(rows) << "\nfused_bi timing:\n"
            << formatTimingSummary(scores[Method::kFusedBI].stats) << "pms timing:\n"
            << formatTimingSummary(scores[Method::kPlainPMS].stats);

  const DepthMetrics fused = averageMetrics(scores[Method::kFusedBI].all);
  const DepthMetrics lidar = averageMetrics(scores[Method::kLidarBI].all);
  EXPECT_LT(fused.mae_mm, lidar.mae_mm) << "seed " << seed;
  EXPECT_LT(fused.rmse_mm, lidar.rmse_mm) << "seed " << seed;
  const DepthMetrics fused_subset = averageMetrics(scores[Method::kFusedBI].pms_frames);
  const DepthMetrics pms = averageMetrics(scores[Method::kPlainPMS].all);
  EXPECT_LT(fused_subset.mae_mm, pms.mae_mm) << "seed " << seed;
  EXPECT_LT(fused_subset.rmse_mm, pms.rmse_mm) << "seed " << seed;
}

}  // namespace
}  // namespace lidar_stereo_fusion
