// rostest of the fusion node (see test_fusion_node.cpp): parameters changed live through
// dynamic_reconfigure (invalid ones refused, naming the value in force; the node's live ones too)
// and the diagnostics on
// output rate and processing time.
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>

#include "fusion_node_fixtures.h"
#include "fusion_test_harness.h"
#include "lidar_stereo_fusion/FusionStats.h"
#include "lidar_stereo_fusion/core/patchmatch.h"

namespace lsf = lidar_stereo_fusion;
using namespace fusion_test;  // NOLINT: the harness of these tests

TEST_F(FusionNode, ParametersChangeLiveAndInvalidOnesAreRejected) {
  const std::string service = h().fusionNode() + "/set_parameters";
  ASSERT_TRUE(ros::service::waitForService(service, 5000));
  auto set = [&](const std::function<void(dynamic_reconfigure::Config&)>& fill,
                 dynamic_reconfigure::Config* result) {
    dynamic_reconfigure::Reconfigure srv;
    fill(srv.request.config);
    const bool ok = ros::service::call(service, srv);
    if (result) *result = srv.response.config;
    return ok;
  };
  auto value = [](const dynamic_reconfigure::Config& c, const std::string& name) {
    for (const auto& d : c.doubles) {
      if (d.name == name) return d.value;
    }
    return std::nan("");
  };

  // alpha + beta + gamma != 1: refused with an error naming the parameter; the response carries
  // the value in force.
  std::size_t mark = h().logMark();
  dynamic_reconfigure::Config result;
  ASSERT_TRUE(set(
      [](dynamic_reconfigure::Config& c) {
        dynamic_reconfigure::DoubleParameter p;
        p.name = "alpha";
        p.value = 0.5;
        c.doubles.push_back(p);
      },
      &result));
  const double default_alpha = lidar_stereo_fusion::PatchMatchParams().alpha;
  EXPECT_DOUBLE_EQ(value(result, "alpha"), default_alpha);
  EXPECT_TRUE(h().waitForLog(mark, {"refused", "alpha + beta + gamma", "alpha = 0.5 (in force: "}))
      << h().logsSince(mark);
  auto stats = goodSetStats();
  ASSERT_TRUE(stats);
  EXPECT_EQ(stats->method, "fused_bi");
  double alpha = 0;
  ros::param::get(h().fusionNode() + "/alpha", alpha);
  EXPECT_DOUBLE_EQ(alpha, default_alpha);

  // An unknown method: refused as asked ("bogus"), not reported as some other change.
  mark = h().logMark();
  ASSERT_TRUE(set(
      [](dynamic_reconfigure::Config& c) {
        dynamic_reconfigure::StrParameter p;
        p.name = "method";
        p.value = "bogus";
        c.strs.push_back(p);
      },
      &result));
  std::string answered;
  for (const auto& p : result.strs) {
    if (p.name == "method") answered = p.value;
  }
  EXPECT_EQ(answered, "fused_bi");
  EXPECT_TRUE(h().waitForLog(mark, {"refused", "method = bogus (in force: fused_bi)"}))
      << h().logsSince(mark);

  // A valid change applies to the next frame.
  ASSERT_TRUE(set(
      [](dynamic_reconfigure::Config& c) {
        dynamic_reconfigure::StrParameter p;
        p.name = "method";
        p.value = "lidar_bi";
        c.strs.push_back(p);
      },
      nullptr));
  stats = goodSetStats();
  ASSERT_TRUE(stats);
  EXPECT_EQ(stats->method, "lidar_bi");
  std::string method;
  ros::param::get(h().fusionNode() + "/method", method);
  EXPECT_EQ(method, "lidar_bi");

  ASSERT_TRUE(set(
      [](dynamic_reconfigure::Config& c) {
        dynamic_reconfigure::StrParameter p;
        p.name = "method";
        p.value = "fused_bi";
        c.strs.push_back(p);
      },
      nullptr));
  stats = goodSetStats();
  ASSERT_TRUE(stats);
  EXPECT_EQ(stats->method, "fused_bi");
}

namespace {
/// Finite depth values [m] of a depth image.
std::vector<float> finiteDepths(const sensor_msgs::Image& depth) {
  std::vector<float> out;
  for (uint32_t r = 0; r < depth.height; ++r) {
    const float* row = reinterpret_cast<const float*>(&depth.data[r * depth.step]);
    for (uint32_t c = 0; c < depth.width; ++c) {
      if (std::isfinite(row[c])) out.push_back(row[c]);
    }
  }
  return out;
}

}  // namespace

// Issue 24: the node's live parameters (ros/node_params.h rows marked live) change through
// dynamic_reconfigure from the next frame; a value outside its row's range is refused with the
// table's sentence, as the algorithm's are.
TEST_F(FusionNode, NodeParametersChangeLiveWithinTheirTableRanges) {
  const std::string service = h().fusionNode() + "/set_parameters";
  ASSERT_TRUE(ros::service::waitForService(service, 5000));
  auto set = [&](dynamic_reconfigure::Config request, dynamic_reconfigure::Config* result) {
    dynamic_reconfigure::Reconfigure srv;
    srv.request.config = request;
    const bool ok = ros::service::call(service, srv);
    if (result) *result = srv.response.config;
    return ok;
  };
  auto one = [](const std::string& name, auto value) {
    dynamic_reconfigure::Config c;
    if constexpr (std::is_same_v<decltype(value), int>) {
      dynamic_reconfigure::IntParameter p;
      p.name = name;
      p.value = value;
      c.ints.push_back(p);
    } else {
      dynamic_reconfigure::DoubleParameter p;
      p.name = name;
      p.value = value;
      c.doubles.push_back(p);
    }
    return c;
  };

  // Out of range: refused, in the words of the table; the response carries the value in force.
  std::size_t mark = h().logMark();
  dynamic_reconfigure::Config result;
  ASSERT_TRUE(set(one("cloud_stride", 0), &result));
  int stride = -1;
  for (const auto& p : result.ints) {
    if (p.name == "cloud_stride") stride = p.value;
  }
  EXPECT_EQ(stride, 1);
  EXPECT_TRUE(h().waitForLog(mark, {"refused", "cloud_stride must be in [1, 64], got 0"}))
      << h().logsSince(mark);

  // max_output_depth applies from the next frame: nothing beyond it, less depth than before.
  auto before = goodSetStats() ? h().image("depth/image_rect") : nullptr;
  ASSERT_TRUE(before);
  std::vector<float> depths = finiteDepths(*before);
  ASSERT_GT(depths.size(), 100u);
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  const double limit = depths[depths.size() / 2];
  ASSERT_TRUE(set(one("max_output_depth", limit), nullptr));
  auto after = goodSetStats() ? h().image("depth/image_rect") : nullptr;
  ASSERT_TRUE(after);
  const std::vector<float> limited = finiteDepths(*after);
  EXPECT_GT(limited.size(), 0u);
  EXPECT_LT(limited.size(), finiteDepths(*before).size());
  EXPECT_LE(*std::max_element(limited.begin(), limited.end()), limit);

  ASSERT_TRUE(set(one("max_output_depth", 0.0), nullptr));
  auto restored = goodSetStats() ? h().image("depth/image_rect") : nullptr;
  ASSERT_TRUE(restored);
  EXPECT_GT(finiteDepths(*restored).size(), limited.size());
}

TEST_F(FusionNode, DiagnosticsReportRateAndProcessingTime) {
  ros::NodeHandle nh;
  std::mutex m;
  std::map<std::string, diagnostic_msgs::DiagnosticStatus> seen;
  auto sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 10, [&](const diagnostic_msgs::DiagnosticArrayConstPtr& msg) {
        std::lock_guard<std::mutex> lock(m);
        for (const auto& s : msg->status) seen[s.name] = s;
      });
  // Keep frames coming so the rate is measured.
  const auto has = [&](const std::string& suffix) {
    std::lock_guard<std::mutex> lock(m);
    for (const auto& kv : seen) {
      if (kv.first.size() >= suffix.size() &&
          kv.first.compare(kv.first.size() - suffix.size(), suffix.size(), suffix) == 0) {
        return true;
      }
    }
    return false;
  };
  // The updater publishes once per diagnostic period (1 s), so keep frames coming for a wall-clock
  // span rather than a frame count: on a fast machine 15 small frames take less than one period.
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(20.0);
  while (ros::WallTime::now() < deadline && !(has(": output") && has(": processing"))) {
    const ros::Time stamp = h().nextStamp();
    h().publishSet(SetSpec(), stamp);
    h().waitForOutputs(stamp);
  }
  ASSERT_TRUE(has(": output"));
  ASSERT_TRUE(has(": processing"));
  std::lock_guard<std::mutex> lock(m);
  for (const auto& kv : seen) {
    if (kv.first.find(": processing") == std::string::npos) continue;
    bool has_time = false;
    for (const auto& v : kv.second.values)
      has_time = has_time || v.key == "processing time mean [ms]";
    EXPECT_TRUE(has_time);
  }
}
