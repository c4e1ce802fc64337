// The launch files' arguments as a user meets them (issue 10), read with `roslaunch --dump-params`
// (no master needed): fusion.launch's `method` does not shadow the params_file unless given;
// zed_vls128.launch sets use_sim_time false and tells the fusion which drivers it started.
#include <cstdio>
#include <fstream>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "run_command.h"

namespace lt = lidar_stereo_fusion::test;

namespace {

/// The parameters roslaunch would set, as its YAML-like dump.
std::string dumpParams(const std::string& launch, const std::string& args = "") {
  const auto [status, output] =
      lt::runCommand("/usr/bin/python3 /usr/bin/roslaunch --dump-params " +
                     std::string(LSF_SOURCE_DIR) + "/launch/" + launch + " " + args);
  EXPECT_EQ(status, 0) << output;
  return output;
}

}  // namespace

TEST(LaunchFiles, MethodArgumentDoesNotShadowTheParamsFile) {
  const std::string yaml = std::string(LSF_BINARY_DIR) + "/test_launch_lidar_bi.yaml";
  std::ofstream(yaml) << "method: lidar_bi\n";
  const std::string from_file = dumpParams("fusion.launch", "params_file:=" + yaml);
  EXPECT_NE(from_file.find("/fusion/fusion/method: lidar_bi"), std::string::npos) << from_file;
  const std::string given = dumpParams("fusion.launch", "params_file:=" + yaml + " method:=pms");
  EXPECT_NE(given.find("/fusion/fusion/method: pms"), std::string::npos) << given;
  const std::string playback =
      dumpParams("playback.launch", "bag:=/nonexistent.bag params_file:=" + yaml);
  EXPECT_NE(playback.find("/fusion/fusion/method: lidar_bi"), std::string::npos) << playback;
}

TEST(LaunchFiles, RigLaunchUsesWallClockAndNamesTheDrivers) {
  const std::string rig = dumpParams("zed_vls128.launch");
  EXPECT_NE(rig.find("/use_sim_time: false"), std::string::npos) << rig;
  EXPECT_NE(rig.find("/fusion/fusion/drivers: "), std::string::npos) << rig;
  // (the dump folds long strings over lines)
  EXPECT_NE(rig.find("ZED (zed_wrapper):"), std::string::npos) << rig;
  EXPECT_NE(rig.find("(velodyne_pointcloud):"), std::string::npos) << rig;
  const std::string without = dumpParams("zed_vls128.launch", "start_zed:=false");
  EXPECT_EQ(without.find("ZED (zed_wrapper): started"), std::string::npos) << without;
}

TEST(LaunchFiles, PresetLiveLoadsConfigLiveEverywhere) {
  // fusion.launch, playback.launch and measure_live.launch take preset:=live; the rig's default is
  // live (README: presets).
  for (const auto& [launch, args] :
       {std::pair<std::string, std::string>{"fusion.launch", "preset:=live"},
        {"playback.launch", "bag:=/nonexistent.bag preset:=live"},
        {"measure_live.launch", "preset:=live"},
        {"zed_vls128.launch", ""}}) {
    const std::string dump = dumpParams(launch, args);
    EXPECT_NE(dump.find("/fusion/fusion/search_scale: 2"), std::string::npos) << launch << "\n"
                                                                              << dump;
    EXPECT_NE(dump.find("/fusion/fusion/intermediate_refine: false"), std::string::npos)
        << launch << "\n"
        << dump;
  }
  const std::string fusion = dumpParams("fusion.launch");
  EXPECT_NE(fusion.find("/fusion/fusion/search_scale: 1"), std::string::npos) << fusion;
  const std::string rig = dumpParams("zed_vls128.launch", "preset:=fusion");
  EXPECT_NE(rig.find("/fusion/fusion/search_scale: 1"), std::string::npos) << rig;
}

TEST(LaunchFiles, PclFiltersAreOffByDefaultAndPassedThroughFromRigAndPlayback) {
  // Off: no filter node and the fusion reads the sweep topic itself.
  const std::string plain = dumpParams("fusion.launch");
  EXPECT_EQ(plain.find("/fusion/self_filter/"), std::string::npos) << plain;
  EXPECT_EQ(plain.find("/fusion/points2_voxel_grid/"), std::string::npos) << plain;
  const std::string box = "self_filter_min:='-3 -1.5 -2.5' self_filter_max:='1.5 1.5 0.5' ";
  for (const auto& [launch, args] : {std::pair<std::string, std::string>{"fusion.launch", ""},
                                     {"playback.launch", "bag:=/nonexistent.bag "},
                                     {"zed_vls128.launch", ""}}) {
    const std::string dump = dumpParams(launch, args + box + "voxel_leaf_size:=0.25");
    for (const char* expected :
         {"/fusion/self_filter/negative: true", "/fusion/self_filter/min_x: -3.0",
          "/fusion/self_filter/min_y: -1.5", "/fusion/self_filter/min_z: -2.5",
          "/fusion/self_filter/max_x: 1.5", "/fusion/self_filter/max_y: 1.5",
          "/fusion/self_filter/max_z: 0.5", "/fusion/points2_voxel_grid/leaf_size: 0.25",
          "/fusion/points2_voxel_grid/filter_field_name: ''"}) {
      EXPECT_NE(dump.find(expected), std::string::npos) << launch << ": " << expected << "\n"
                                                        << dump;
    }
  }
}
