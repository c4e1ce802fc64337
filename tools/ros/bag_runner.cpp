// bag_runner: the fusion on every image set of a recorded drive (one or several ROS 1 bags read
// as one recording), offline, without a roscore. Sets are paired with sweeps exactly as the live
// node pairs them (BagPairing: the node's synchroniser and sweep matcher, ROS time = bag time),
// the extrinsics come from /tf_static and /tf in the bag at the sweep stamp, and nothing is
// dropped for speed. The run itself is BagRun (bag_run.h); this file is the command line. See
// kUsage and doc/tools.md.
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "bag_runner/bag_run.h"
#include "lidar_stereo_fusion/io/cli.h"

namespace lsf = lidar_stereo_fusion;
namespace fs = std::filesystem;

namespace {

const char* const kUsage =
    R"(Usage: bag_runner --bag FILE [--bag FILE ...] --out DIR [options] [NAME:=TOPIC ...]

Runs LiDAR-stereo fusion on every image set of a recorded drive (several --bag files are read as
one recording) and writes DIR/<sec>.<nsec>.png per set (the left image stamp; KITTI depth format:
uint16, metres * 256, 0 = none) and DIR/frames.csv (one row per image set: ok / skipped / failed
with the reason, ms per stage, coverage, ring method). Image sets and sweeps are paired as the
fusion nodelet pairs them; the LiDAR -> camera transform is read from /tf_static and /tf. Images
recorded as sensor_msgs/CompressedImage (png, jpeg) are decoded. DIR/manifest.txt records what
made the outputs (bags, topics, parameters, version): a later run into DIR with anything else
refuses, saying what differs. No output may be an input (refused, naming both).

Options:
  --bag FILE          input bag (repeat for a recording split into several bags)
  --out DIR           output folder (created)
  --params YAML       algorithm parameters (config/fusion.yaml layout; default: the built-in ones)
  --node-params YAML  node parameters (config/fusion_node.yaml layout, checked as the node checks
                      them; used here: the synchronisation, num_rings, max_output_depth,
                      cloud_stride and the ego-motion compensation from the bag's /tf with
                      fixed_frame, motion_samples, motion_failure, max_point_time; doc/motion.md)
  --approximate-sync  ApproximateTime image sync (as approximate_sync: true)
  --method NAME       fused_bi | fused_bf | pms | lidar_bi | lidar_bf (overrides --params)
  --start S, --end S  only the image sets whose left image was recorded in [S, E) seconds after
                      the start of the recording (messages from --lead-in seconds before S are
                      read, so the pairing is the same as in a whole run); a window without an
                      image set is an error
  --lead-in S         default 3
  --disparity         also DIR/disparity/<stamp>.png (uint16, px * 256, 0 = none)
  --confidence        also DIR/confidence/<stamp>.png (uint16, confidence * 65535)
  --cloud             also DIR/cloud/<stamp>.pcd (the points of points2: x y z rgb, left optical
                      frame, as kitti_runner --save-pcd)
  --out-bag FILE      the nodelet's output topics (under --ns, default /fusion), stamped as
                      their inputs, at the left image's bag time
  --frames-csv FILE   write the rows there instead of DIR/frames.csv
  --resume            keep the sets whose files exist (and their rows); DIR's manifest must match
  --force             remove the outputs of an earlier run in DIR first (whatever made them)
  --prepare           check the inputs and prepare DIR (manifest, --force, leftovers of a killed
                      run), then stop (lsf_batch, before a bag's tasks)
  --allow-empty       a time window without an image set is no error (lsf_batch's chunks)
  --help              this text
Remaps (the nodelet's input names): left/image_rect_color:=TOPIC, left/camera_info:=TOPIC,
right/image_rect_color:=TOPIC, right/camera_info:=TOPIC, velodyne_points:=TOPIC (defaults:
/stereo/..., /velodyne_points as written by kitti_to_bag; relative topics are resolved in /, an
image topic recorded only as TOPIC/compressed is read there); output names (depth/image_rect,
...) for --out-bag. Any other name is refused.

Exit status: 0 when no set failed, 1 when any set failed (each is named) or on bad input (a bag
that cannot be read, a missing input topic, an empty time window, an output that is an input, an
output folder that cannot be written or holds another run's outputs), 2 on a bad command line.
)";

/// --bag (repeated) and NAME:=TOPIC are taken out; the rest goes to CommandLine.
std::vector<const char*> splitArguments(int argc, char** argv, lsf::BagRunOptions& o) {
  std::vector<const char*> rest = {argv[0]};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--bag") {
      if (i + 1 >= argc) throw lsf::UsageError("--bag needs a file");
      o.bags.push_back(argv[++i]);
    } else if (a.find(":=") != std::string::npos && a.rfind("--", 0) != 0) {
      lsf::applyRemap(a, o.topics, o.outputs.remaps);
    } else {
      rest.push_back(argv[i]);
    }
  }
  return rest;
}

void readWindow(const lsf::CommandLine& cl, lsf::BagRunOptions& o) {
  o.start = cl.doubleValue("--start", -1, 0, 1e9);
  o.end = cl.doubleValue("--end", -1, 0, 1e9);
  if (cl.has("--end") && o.end <= 0) {
    throw lsf::UsageError("--end " + cl.value("--end") + ": the window [start, end) is empty");
  }
  if (o.start >= 0 && o.end >= 0 && o.end <= o.start) {
    throw lsf::UsageError("--end " + cl.value("--end") + " <= --start " + cl.value("--start") +
                          ": the window [start, end) is empty");
  }
  o.lead_in = cl.doubleValue("--lead-in", 3.0, 0, 3600);
}

lsf::BagRunOptions parseOptions(int argc, char** argv) {
  lsf::BagRunOptions o;
  const std::vector<const char*> rest = splitArguments(argc, argv, o);
  const lsf::CommandLine cl(
      static_cast<int>(rest.size()), rest.data(),
      {"--out", "--params", "--node-params", "--method", "--start", "--end", "--lead-in",
       "--out-bag", "--ns", "--frames-csv"},
      {"--disparity", "--confidence", "--cloud", "--resume", "--approximate-sync", "--force",
       "--prepare", "--allow-empty", "--help"});
  if (cl.has("--help")) return lsf::BagRunOptions();
  o.outputs.dir = cl.value("--out");
  if (o.bags.empty()) throw lsf::UsageError("--bag is required");
  if (o.outputs.dir.empty()) throw lsf::UsageError("--out is required");
  o.params = cl.value("--params");
  o.node_params = cl.value("--node-params");
  if (cl.has("--method")) {
    o.method = cl.choice("--method", "", {"fused_bi", "fused_bf", "pms", "lidar_bi", "lidar_bf"});
  }
  readWindow(cl, o);
  o.outputs.out_bag = cl.value("--out-bag");
  o.outputs.ns = cl.value("--ns", "/fusion");
  o.outputs.disparity = cl.has("--disparity");
  o.outputs.confidence = cl.has("--confidence");
  o.outputs.cloud = cl.has("--cloud");
  o.frames_csv = cl.value("--frames-csv", (fs::path(o.outputs.dir) / "frames.csv").string());
  o.resume = cl.has("--resume");
  o.force = cl.has("--force");
  o.prepare = cl.has("--prepare");
  o.allow_empty = cl.has("--allow-empty");
  o.approximate_sync = cl.has("--approximate-sync");
  if (o.resume && !o.outputs.out_bag.empty()) {
    throw lsf::UsageError(
        "--out-bag with --resume would hold only the sets processed now: run without --resume");
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  lsf::BagRunOptions options;
  try {
    options = parseOptions(argc, argv);
  } catch (const lsf::UsageError& e) {
    std::cerr << "bag_runner: " << e.what() << "\n\n" << kUsage;
    return 2;
  }
  if (options.bags.empty()) {  // --help
    std::cout << kUsage;
    return 0;
  }
  ros::Time::init();  // ROS time is then set to each message's bag time (BagPairing)
  try {
    return lsf::BagRun(options).run();
  } catch (const std::exception& e) {
    std::cerr << "\nbag_runner: error: " << e.what() << "\n";
    return 1;
  }
}
