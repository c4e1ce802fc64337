// Plain PMS (FusionParams::plainPmsParams) under every shipped preset: the Bleyer et al. baseline
// runs at full size only, so a preset that searches only at a coarse level (live: search_scale 2)
// must still give valid parameters (it threw "search_scale must be 1 or coarse_scale^k" before).
#include <string>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/io/params_yaml.h"

namespace lidar_stereo_fusion {
namespace {

TEST(PlainPmsParams, EveryPresetGivesValidFullSizeParams) {
  for (const char* preset : {"fusion", "live", "paper"}) {
    FusionParams params;
    loadParamsYaml(std::string(LSF_SOURCE_DIR) + "/config/" + preset + ".yaml", params);
    const PatchMatchParams pms = FusionParams::plainPmsParams(params.patchmatch);
    EXPECT_NO_THROW(pms.validate()) << preset;
    EXPECT_EQ(pms.coarse_scale, 1) << preset;
    EXPECT_EQ(pms.search_scale, 1) << preset;
    params.method = Method::kPlainPMS;
    EXPECT_NO_THROW(FusionPipeline{params}) << preset;
  }
}

}  // namespace
}  // namespace lidar_stereo_fusion
