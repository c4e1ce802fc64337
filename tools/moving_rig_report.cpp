// moving_rig_report: what a moving rig costs the fusion and what ego-motion compensation gives
// back, on the synthetic street with exact ground truth at the image instant (sim/moving_rig.h).
// For each speed and camera/LiDAR offset the sweep is taken while the rig drives (the LiDAR spins
// clockwise, each firing from the pose at its time), then fed as taken and compensated to the
// image instant (the motion sampled at 5 instants over the sweep, as the nodelet does from TF).
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "lidar_stereo_fusion/io/cli.h"
#include "lidar_stereo_fusion/io/params_yaml.h"
#include "lidar_stereo_fusion/io/simd_env.h"
#include "lidar_stereo_fusion/sim/moving_rig.h"

namespace lsf = lidar_stereo_fusion;

namespace {

const char* const kUsage = R"(Usage: moving_rig_report [options]

Prints a Markdown table: per method, speed and LiDAR offset, the disparity MAE and the > 3 px rate
in the LiDAR's field of view (empty pixels filled like the KITTI devkit), with and without
ego-motion compensation, and the MAE of the projected LiDAR points alone.

Options:
  --size WxH          image size of the synthetic street (default 1242x375, KITTI's)
  --rings 64|128      LiDAR rings (default 64)
  --speeds <list>     comma-separated speeds [m/s] (default 0,10,20)
  --offsets <list>    comma-separated offsets [s] of the LiDAR facing ahead after the image
                      instant (default 0,0.05)
  --methods <list>    fused, lidar_bi, pms, paper (config/paper.yaml) (default all)
  --frames N          frames 1..N of the drive, scores averaged (default 3)
  --help              this text
)";

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream list(text);
  for (std::string item; std::getline(list, item, ',');) items.push_back(item);
  return items;
}

std::vector<double> numbers(const std::string& option, const std::string& text, double max) {
  std::vector<double> values;
  for (const std::string& item : split(text)) {
    try {
      size_t used = 0;
      const double v = std::stod(item, &used);
      if (used != item.size() || !(v >= -max && v <= max)) throw std::invalid_argument(item);
      values.push_back(v);
    } catch (const std::exception&) {
      throw lsf::UsageError(option + ": '" + item + "' is not a number in [-" +
                            std::to_string(max) + ", " + std::to_string(max) + "]");
    }
  }
  if (values.empty()) throw lsf::UsageError(option + ": empty list");
  return values;
}

int run(int argc, char** argv) {
  const lsf::CommandLine cl(
      argc, argv, {"--size", "--rings", "--speeds", "--offsets", "--methods", "--frames"}, {});
  int w = 1242, h = 375;
  const std::string size = cl.value("--size", "1242x375");
  if (std::sscanf(size.c_str(), "%dx%d", &w, &h) != 2 || w < 64 || h < 32 || w > 4096 || h > 4096) {
    throw lsf::UsageError("--size wants WxH with 64 <= W <= 4096, 32 <= H <= 4096, got '" + size +
                          "'");
  }
  lsf::sim::SyntheticParams base = lsf::sim::SyntheticParams().resized(w, h);
  base.rings = std::stoi(cl.choice("--rings", "64", {"64", "128"}));
  const std::vector<double> speeds = numbers("--speeds", cl.value("--speeds", "0,10,20"), 100.0);
  const std::vector<double> offsets = numbers("--offsets", cl.value("--offsets", "0,0.05"), 0.1);
  std::vector<std::pair<std::string, lsf::FusionParams>> methods;
  for (const std::string& name : split(cl.value("--methods", "fused,lidar_bi,pms,paper"))) {
    lsf::FusionParams params;
    if (name == "lidar_bi" || name == "pms") {
      params.method = lsf::parseMethod(name);
    } else if (name == "paper") {
      lsf::loadParamsYaml(std::string(LSF_SOURCE_DIR) + "/config/paper.yaml", params);
    } else if (name != "fused") {
      throw lsf::UsageError("--methods: unknown method '" + name +
                            "' (valid: fused, lidar_bi, pms, paper)");
    }
    lsf::applySimdEnvironment(params);
    methods.emplace_back(name, params);
  }
  std::cout << "Synthetic street " << w << "x" << h << ", " << base.rings
            << " rings; MAE and > 3 px in the LiDAR's field of view (disparity, filled like the "
               "KITTI devkit)\n\n"
            << lsf::sim::formatMovingRig(lsf::sim::runMovingRig(
                   base, speeds, offsets, methods, cl.intValue("--frames", 3, 1, 100)));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return lsf::toolMain("moving_rig_report", kUsage, argc, argv, [&] { return run(argc, argv); });
}
