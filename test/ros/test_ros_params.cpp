// The parameter tables (core/param_table.h, ros/node_params.h) against everything made from
// them: dynamic_reconfigure (cfg/Fusion.cfg), the YAML files, the node's YAML reader and the
// checks' wording. That the generated files are up to date: test/tools/test_lsf_params.cpp.
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include <dynamic_reconfigure/Config.h>
#include <opencv2/core.hpp>

#include "lidar_stereo_fusion/io/params_yaml.h"
#include "lidar_stereo_fusion/io/text_file.h"
#include "lidar_stereo_fusion/ros/ros_params.h"

namespace lsf = lidar_stereo_fusion;

// --- parameters ----------------------------------------------------------------------------------
namespace {
std::map<std::string, std::string> configEntries(const lsf::FusionConfig& config) {
  dynamic_reconfigure::Config msg;
  config.__toMessage__(msg);
  std::map<std::string, std::string> out;
  for (const auto& p : msg.doubles) out[p.name] = "double " + std::to_string(p.value);
  for (const auto& p : msg.ints) out[p.name] = "int " + std::to_string(p.value);
  for (const auto& p : msg.bools) out[p.name] = std::string("bool ") + (p.value ? "true" : "false");
  for (const auto& p : msg.strs) out[p.name] = "string " + p.value;
  return out;
}
}  // namespace

TEST(RosParams, ReconfigureHasExactlyTheTableWithTheSameNamesAndGroups) {
  // One name per parameter (issue 10): the cfg name is the table's, the cfg group its group.
  const auto entries = configEntries(lsf::FusionConfig::__getDefault__());
  std::map<std::string, std::string> cfg_group;
  for (const auto& g : lsf::FusionConfig::__getDescriptionMessage__().groups) {
    for (const auto& param : g.parameters)
      cfg_group[param.name] = g.name == "Default" ? "" : g.name;
  }
  std::set<std::string> listed;
  std::vector<lsf::ParamInfo> live = lsf::ros_params::listParams();
  for (const auto& info : lsf::ros_params::listNodeParams()) {
    if (info.live) {
      live.push_back(info);
    } else {
      EXPECT_FALSE(entries.count(info.name)) << info.name << " is read at start-up only";
    }
  }
  for (const auto& info : live) {
    listed.insert(info.name);
    ASSERT_TRUE(entries.count(info.name)) << info.name << " is missing from cfg/Fusion.cfg";
    EXPECT_EQ(entries.at(info.name).substr(0, info.type.size()), info.type) << info.name;
    EXPECT_EQ(cfg_group[info.name], info.group) << info.name << ": group in cfg/Fusion.cfg";
  }
  for (const auto& kv : entries) {
    EXPECT_TRUE(listed.count(kv.first))
        << kv.first << " in cfg/Fusion.cfg is no live row of the parameter tables";
  }
}

TEST(RosParams, ReconfigureHasNoSliderRangeThatWouldClampSilently) {
  // Out-of-range values must reach the node, which refuses them visibly (issue 10).
  const auto min = configEntries(lsf::FusionConfig::__getMin__());
  const auto max = configEntries(lsf::FusionConfig::__getMax__());
  for (const auto& info : lsf::ros_params::listParams()) {
    if (info.type == "double") {
      EXPECT_EQ(min.at(info.name), "double -inf") << info.name;
      EXPECT_EQ(max.at(info.name), "double inf") << info.name;
    } else if (info.type == "int") {
      EXPECT_EQ(min.at(info.name), "int " + std::to_string(std::numeric_limits<int>::min()))
          << info.name;
    }
  }
}

TEST(RosParams, ReconfigureDefaultsAreTheStructDefaults) {
  const auto cfg = configEntries(lsf::FusionConfig::__getDefault__());
  const auto structs = configEntries(lsf::ros_params::toConfig(lsf::FusionParams()));
  for (const auto& kv : structs) {
    EXPECT_EQ(cfg.at(kv.first), kv.second) << kv.first << ": cfg default vs FusionParams default";
  }
}

TEST(RosParams, ConfigRoundTripKeepsEveryField) {
  lsf::FusionParams p;
  p.method = lsf::Method::kFusedBF;
  p.projection.max_depth = 77.0;
  p.bi.search_lines = 1;
  p.bf.sigma_range = 3.5;
  p.patchmatch.window_radius = 9;
  p.patchmatch.slanted = false;
  p.patchmatch.seed = 1234;
  const lsf::FusionParams q = lsf::ros_params::fromConfig(lsf::ros_params::toConfig(p));
  EXPECT_EQ(lsf::ros_params::describeChanges(p, q), "");
  EXPECT_EQ(q.method, lsf::Method::kFusedBF);
  EXPECT_EQ(q.patchmatch.seed, 1234u);
  EXPECT_NE(lsf::ros_params::describeChanges(lsf::FusionParams(), p)
                .find("window_radius: " + std::to_string(lsf::PatchMatchParams().window_radius) +
                      " -> 9"),
            std::string::npos)
      << lsf::ros_params::describeChanges(lsf::FusionParams(), p);
}

TEST(RosParams, UnknownMethodInReconfigureIsNamed) {
  lsf::FusionConfig config = lsf::FusionConfig::__getDefault__();
  config.method = "sgbm";
  try {
    lsf::ros_params::fromConfig(config);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("method"), std::string::npos) << e.what();
  }
}

namespace {
/// A YAML file as an OpenCV FileStorage (rosparam files have no "%YAML:1.0" directive).
cv::FileStorage openRosparamYaml(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << "%YAML:1.0\n---\n" << in.rdbuf();
  return cv::FileStorage(text.str(), cv::FileStorage::READ | cv::FileStorage::MEMORY);
}
}  // namespace

TEST(RosParams, EveryFieldTheCoreYamlWriterKnowsIsARosParameter) {
  // saveParamsYaml writes every field of the table, at the top level, under the one name.
  const std::string path = std::string(LSF_BINARY_DIR) + "/test_ros_unit_params.yaml";
  lsf::saveParamsYaml(path, lsf::FusionParams());
  cv::FileStorage fs = openRosparamYaml(path);
  ASSERT_TRUE(fs.isOpened());
  std::set<std::string> core;
  for (const cv::FileNode& node : fs.root()) {
    EXPECT_FALSE(node.isMap()) << node.name() << ": no sections";
    core.insert(node.name());
  }
  std::set<std::string> ros;
  for (const auto& info : lsf::ros_params::listParams()) ros.insert(info.name);
  EXPECT_EQ(core, ros);
}

TEST(RosParams, ShippedYamlHasEveryParameterAtItsDefaultUnderTheOneName) {
  const std::string path = std::string(LSF_SOURCE_DIR) + "/config/fusion.yaml";
  lsf::FusionParams loaded;
  ASSERT_NO_THROW(lsf::loadParamsYaml(path, loaded));
  EXPECT_EQ(lsf::ros_params::describeChanges(lsf::FusionParams(), loaded), "")
      << "config/fusion.yaml documents the struct defaults";
  cv::FileStorage fs = openRosparamYaml(path);
  ASSERT_TRUE(fs.isOpened());
  std::set<std::string> keys;
  for (const cv::FileNode& node : fs.root()) keys.insert(node.name());
  std::set<std::string> names;
  for (const auto& info : lsf::ros_params::listParams()) names.insert(info.name);
  EXPECT_EQ(keys, names) << "config/fusion.yaml: exactly the table's names, no sections";
}

TEST(RosParams, EveryNameIsUniqueAcrossBothTables) {
  // One namespace: the nodelet's private parameters and one dynamic_reconfigure server.
  std::map<std::string, int> seen;
  for (const auto& info : lsf::ros_params::listParams()) ++seen[info.name];
  for (const auto& info : lsf::ros_params::listNodeParams()) ++seen[info.name];
  for (const auto& [name, count] : seen) EXPECT_EQ(count, 1) << name;
}

TEST(RosParams, LiveNodeRowsRoundTripThroughReconfigureAndOthersStay) {
  lsf::NodeParams node;
  node.max_output_depth = 12.5;
  node.cloud_stride = 3;
  node.fixed_frame = "odom";
  node.motion_failure = "skip";
  node.queue_size = 9;  // start-up only: not in the config
  const lsf::FusionConfig config = lsf::ros_params::toConfig(lsf::FusionParams(), node);
  lsf::NodeParams back;
  lsf::ros_params::fromConfig(config, &back);
  EXPECT_EQ(back.max_output_depth, 12.5);
  EXPECT_EQ(back.cloud_stride, 3);
  EXPECT_EQ(back.fixed_frame, "odom");
  EXPECT_EQ(back.motion_failure, "skip");
  EXPECT_EQ(back.queue_size, lsf::NodeParams().queue_size);
  EXPECT_EQ(lsf::ros_params::describeChanges(lsf::NodeParams(), back),
            "fixed_frame:  -> odom, motion_failure: uncompensated -> skip, cloud_stride: 1 -> 3, "
            "max_output_depth: 0.0 -> 12.5");
}

TEST(NodeParams, ValidateSaysTheTablesSentence) {
  lsf::NodeParams p;
  EXPECT_NO_THROW(p.validate());
  const auto message = [](const lsf::NodeParams& bad) {
    try {
      bad.validate();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  p.queue_size = 0;
  EXPECT_EQ(message(p), "NodeParams: queue_size must be >= 1, got 0");
  p = lsf::NodeParams();
  p.fresh_wait = 1.5;
  EXPECT_EQ(message(p), "NodeParams: fresh_wait must be in [0, 1] s, got 1.5");
  p = lsf::NodeParams();
  p.max_point_time = 0.0;
  EXPECT_EQ(message(p), "NodeParams: max_point_time must be in (0, 10] s, got 0");
  p = lsf::NodeParams();
  p.motion_failure = "drop";
  EXPECT_EQ(message(p),
            "NodeParams: motion_failure must be one of uncompensated, skip, got 'drop'");
  p = lsf::NodeParams();
  p.tf_timeout = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(message(p), "NodeParams: tf_timeout must be in [0, 10] s, got nan");
  p = lsf::NodeParams();
  p.diag_min_rate = 200.0;
  EXPECT_EQ(message(p),
            "NodeParams: diagnostics/min_rate must be <= diagnostics/max_rate (100.0) Hz, got "
            "200.0");
}

namespace {
std::string writeTemp(const std::string& name, const std::string& text) {
  const std::string path = std::string(LSF_BINARY_DIR) + "/" + name;
  std::ofstream(path) << text;
  return path;
}
std::string nodeYamlError(const std::string& text) {
  try {
    lsf::readNodeParamsYaml(writeTemp("test_node_params.yaml", text));
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}
}  // namespace

TEST(NodeParams, YamlReadsEveryRowAndRefusesWhatTheTableRefuses) {
  const lsf::NodeParams shipped =
      lsf::readNodeParamsYaml(std::string(LSF_SOURCE_DIR) + "/config/fusion_node.yaml");
  EXPECT_EQ(lsf::ros_params::describeChanges(lsf::NodeParams(), shipped), "")
      << "config/fusion_node.yaml documents the defaults";

  const lsf::NodeParams p = lsf::readNodeParamsYaml(
      writeTemp("test_node_params_ok.yaml",
                "approximate_sync: true\nfixed_frame: odom  # comment\nmotion_failure: skip\n"
                "max_time_offset: 0.08\ndiagnostics:\n  min_rate: 5.0\n"));
  EXPECT_TRUE(p.approximate_sync);
  EXPECT_EQ(p.fixed_frame, "odom");
  EXPECT_EQ(p.motion_failure, "skip");
  EXPECT_EQ(p.max_time_offset, 0.08);
  EXPECT_EQ(p.diag_min_rate, 5.0);

  EXPECT_NE(nodeYamlError("queue_size: 0\n")
                .find("invalid value: NodeParams: queue_size must be "
                      ">= 1, got 0"),
            std::string::npos)
      << nodeYamlError("queue_size: 0\n");
  EXPECT_NE(nodeYamlError("queu_size: 3\n").find("unknown key 'queu_size'"), std::string::npos)
      << nodeYamlError("queu_size: 3\n");
  EXPECT_NE(nodeYamlError("motion_failure: drop\n")
                .find("key 'motion_failure' must be one of uncompensated, skip, got 'drop'"),
            std::string::npos)
      << nodeYamlError("motion_failure: drop\n");
  EXPECT_NE(nodeYamlError("approximate_sync: maybe\n")
                .find("key 'approximate_sync' must be true or false"),
            std::string::npos);
  EXPECT_NE(nodeYamlError("diagnostics:\n  min_rat: 1.0\n").find("unknown key 'min_rat'"),
            std::string::npos)
      << nodeYamlError("diagnostics:\n  min_rat: 1.0\n");
  EXPECT_NE(nodeYamlError("sync:\n  queue_size: 3\n").find("unknown key 'sync'"), std::string::npos)
      << "the node's groups are no sections";
}

TEST(RosParams, LaunchArgumentsNamedLikeAParameterLeaveItsDefaultToTheTable) {
  // An argument with its own default would override the YAML file loaded before it, and say the
  // default a second time; empty = the file's (and so the table's) value.
  std::set<std::string> names;
  for (const auto& info : lsf::ros_params::listParams()) names.insert(info.name);
  for (const auto& info : lsf::ros_params::listNodeParams()) names.insert(info.name);
  int checked = 0;
  for (const std::string launch :
       {"fusion.launch", "playback.launch", "measure_live.launch", "zed_vls128.launch"}) {
    const std::string text =
        lsf::readTextFile(std::string(LSF_SOURCE_DIR) + "/launch/" + launch, "launch file");
    const std::string tag = "<arg name=\"";
    for (size_t i = text.find(tag); i != std::string::npos; i = text.find(tag, i + 1)) {
      const size_t name_end = text.find('"', i + tag.size());
      const std::string name = text.substr(i + tag.size(), name_end - i - tag.size());
      const size_t close = text.find('>', name_end);
      const std::string rest = text.substr(name_end, close - name_end);
      if (!names.count(name) || rest.find("default=\"") == std::string::npos) continue;
      ++checked;
      EXPECT_NE(rest.find("default=\"\""), std::string::npos)
          << launch << ": argument " << name << " repeats a default of the parameter tables";
    }
  }
  EXPECT_GE(checked, 5);
}
