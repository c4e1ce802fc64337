// Issue 31 on the fused result: a KITTI sweep fed without its ring field, shuffled or in
// image-row order, gets its beams back from the beam model, so the fused depth and LiDAR-only BI*
// on the ring hold-out (ring32: rings % 2 == 0 fed, the others the reference; eval/holdout.h) are
// within 1 % MAE of the ordered sweep's. Elevation rings, today's fallback before the beam model,
// are shown not to be: the test can tell.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "data_guard.h"
#include "lidar_stereo_fusion/core/metrics.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/eval/holdout.h"
#include "lidar_stereo_fusion/io/kitti.h"
#include "ring_variants.h"

namespace lidar_stereo_fusion {
namespace {

const char* const kDrive = "kitti_raw/2011_09_26/2011_09_26_drive_0009_sync";

/// MAE [mm] of `method` on the frame with `fed` as the sweep, filled like the KITTI devkit.
double holdoutMae(const kitti::FrameData& data, const kitti::Calibration& calib,
                  const LidarCloud& fed, const cv::Mat1f& reference, Method method) {
  FusionParams params;
  params.method = method;
  FusionPipeline pipeline(params);
  const FusionInput input{data.left, data.right, fed, calib.T_cam_velo, calib.camera};
  const cv::Mat1f depth = pipeline.process(input).depth;
  return evaluateDepth(fillLikeDevkit(depth, MapKind::kDepth), reference, calib.camera).mae_mm;
}

/// The four ways of feeding the frame's ring32 hold-out sweep.
struct FedSweeps {
  std::vector<std::string> names;
  std::vector<LidarCloud> clouds;
};

FedSweeps fedSweeps(const LidarCloud& fed, const kitti::Calibration& calib, unsigned seed) {
  test::RingVariant shuffled = test::makeVariant(fed, test::shuffledOrder(fed, seed));
  test::RingVariant rows = test::makeVariant(fed, test::imageRowOrder(fed, calib, false));
  LidarCloud by_elevation = shuffled.cloud;
  recoverRingsByElevation(by_elevation, 64);
  for (auto* variant : {&shuffled, &rows}) {
    const RingRecovery r = ensureRings(variant->cloud, /*has_ring_field=*/false, 64);
    EXPECT_EQ(r.source, RingSource::kBeamModel) << r.fallbacks;
    EXPECT_EQ(r.rings, 32);
  }
  return {
      {"ordered", "shuffled (seed " + std::to_string(seed) + ")", "image rows", "elevation rings"},
      {fed, shuffled.cloud, rows.cloud, by_elevation}};
}

TEST(RingRecoveryFusion, ShuffledAndRowOrderedSweepsFuseWithin1PercentOfTheOrderedOne) {
  LSF_REQUIRE_DATA(kDrive);
  const std::string drive = test::dataPath(kDrive);
  const kitti::Calibration calib = kitti::readCalibration(kitti::calibrationDirOf(drive));
  const std::vector<kitti::Frame> frames = kitti::listFrames(drive);
  ASSERT_EQ(frames.size(), 11u);
  for (const std::size_t f : {0u, 5u}) {
    const kitti::FrameData data = kitti::loadFrame(frames[f], calib.camera);
    ASSERT_EQ(data.rings.source, RingSource::kSweepOrder);
    const HoldoutCase holdout =
        makeRingHoldout(data.cloud, calib.T_cam_velo, calib.camera, ProjectionParams(), 2);
    const FedSweeps sweeps = fedSweeps(holdout.fed, calib, static_cast<unsigned>(f) + 5);
    for (const Method method : {Method::kFusedBI, Method::kLidarBI}) {
      std::vector<double> mae;
      for (std::size_t i = 0; i < sweeps.clouds.size(); ++i) {
        mae.push_back(holdoutMae(data, calib, sweeps.clouds[i], holdout.reference_depth, method));
        std::printf("[ rings ] frame %s, %s, ring32, %-18s MAE %.1f mm\n", frames[f].name.c_str(),
                    methodName(method).c_str(), sweeps.names[i].c_str(), mae.back());
      }
      const std::string where = frames[f].name + ", " + methodName(method) + ", ";
      EXPECT_NEAR(mae[1], mae[0], 0.01 * mae[0]) << where << sweeps.names[1];
      EXPECT_NEAR(mae[2], mae[0], 0.01 * mae[0]) << where << sweeps.names[2];
      EXPECT_GT(mae[3], 1.01 * mae[0]) << where << "elevation rings: the test could not tell";
    }
  }
}

}  // namespace
}  // namespace lidar_stereo_fusion
