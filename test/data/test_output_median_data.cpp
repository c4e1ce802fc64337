// The output median keeps the LiDAR's points on the real KITTI drive 0009 (core/output_median.h):
// wherever the output without a median agrees with a measured point (one that BI*'s Algorithm 1
// and step 2b leave on the scan lines; within edge_tolerance), the
// output with the median has that very value; a plain 3x3 median of the same output would move
// more than 50 of them by over 1 px (on frame 20: one-pixel columns of poles and edges, 114 of
// them more than 3 m). Frames 0 and 20, both presets, the full sweep in.
#include <cmath>
#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include "data/data_guard.h"
#include "lidar_stereo_fusion/core/output_median.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "lidar_stereo_fusion/io/params_yaml.h"

namespace lidar_stereo_fusion {
namespace {

const char* const kDrive = "kitti_raw/2011_09_26/2011_09_26_drive_0009_sync";

void expectMeasuredPointsKept(FusionParams params, const std::string& preset) {
  const std::string drive = test::dataPath(kDrive);
  const auto calib = kitti::readCalibration(kitti::calibrationDirOf(drive));
  const float tolerance = static_cast<float>(params.confidence.edge_tolerance);
  ASSERT_EQ(params.patchmatch.output_median, 3);
  FusionParams without = params;
  without.patchmatch.output_median = 0;
  FusionPipeline with_median(params), no_median(without);
  for (const auto& frame : kitti::listFrames(drive)) {
    if (frame.name != "0000000000" && frame.name != "0000000020") continue;
    const auto data = kitti::loadFrame(frame, calib.camera);
    const FusionInput input{data.left, data.right, data.cloud, calib.T_cam_velo, calib.camera};
    const FusionResult kept = with_median.process(input);
    const FusionResult raw = no_median.process(input);
    ScanLines lines = completeScanLines(raw.sparse, params.bi);
    removeOccludedPoints(lines, data.left, params.bi);  // stage 2's steps 2 and 2b, as the pipeline
    removeParallaxHidden(lines, calib.camera, calib.T_cam_velo.translation(), params.bi);
    const cv::Mat1f measured = measuredPoints(raw.sparse.disparity, lines.disparity);
    const cv::Mat1f plain = medianOfValues(raw.disparity, 3);
    int confirmed = 0, moved = 0, moved_by_plain = 0;
    for (int y = 0; y < measured.rows; ++y) {
      for (int x = 0; x < measured.cols; ++x) {
        const float m = measured(y, x), d = raw.disparity(y, x);
        if (!(m > 0.f) || !(std::abs(d - m) <= tolerance)) continue;
        ++confirmed;
        if (kept.disparity(y, x) != d) ++moved;
        if (std::abs(plain(y, x) - d) > 1.f) ++moved_by_plain;
      }
    }
    std::cout << preset << " " << frame.name << ": " << confirmed << " measured points confirmed, "
              << moved << " moved by the median (a plain median: " << moved_by_plain << ")\n";
    EXPECT_GT(confirmed, 15000) << preset << " " << frame.name;
    EXPECT_EQ(moved, 0) << preset << " " << frame.name;
    EXPECT_GT(moved_by_plain, 50) << preset << " " << frame.name;  // the test can fail
  }
}

TEST(OutputMedianData, KeepsTheLidarPointsTheOutputAgreesWithDefaultPreset) {
  LSF_REQUIRE_DATA(kDrive);
  expectMeasuredPointsKept(FusionParams(), "fusion");
}

TEST(OutputMedianData, KeepsTheLidarPointsTheOutputAgreesWithLivePreset) {
  LSF_REQUIRE_DATA(kDrive);
  FusionParams live;
  loadParamsYaml(std::string(LSF_SOURCE_DIR) + "/config/live.yaml", live);
  expectMeasuredPointsKept(live, "live");
}

}  // namespace
}  // namespace lidar_stereo_fusion
