// bag_runner: the fusion on every image set of a recorded drive (one or several ROS 1 bags read
// as one recording), offline, without a roscore. Sets are paired with sweeps exactly as the live
// node pairs them (BagPairing: the node's synchroniser and sweep matcher, ROS time = bag time),
// the extrinsics come from /tf_static and /tf in the bag at the sweep stamp, and nothing is
// dropped for speed. See kUsage and doc/tools.md.
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2/exceptions.h>
#include <tf2_eigen/tf2_eigen.h>

#include "lidar_stereo_fusion/io/cli.h"
#include "lidar_stereo_fusion/io/params_yaml.h"
#include "lidar_stereo_fusion/io/report.h"
#include "lidar_stereo_fusion/ros/bag_outputs.h"
#include "lidar_stereo_fusion/ros/bag_pairing.h"
#include "lidar_stereo_fusion/ros/ego_motion.h"

namespace lsf = lidar_stereo_fusion;
namespace fs = std::filesystem;

namespace {

const char* const kUsage =
    R"(Usage: bag_runner --bag FILE [--bag FILE ...] --out DIR [options] [NAME:=TOPIC ...]

Runs LiDAR-stereo fusion on every image set of a recorded drive (several --bag files are read as
one recording) and writes DIR/<sec>.<nsec>.png per set (the left image stamp; KITTI depth format:
uint16, metres * 256, 0 = none) and DIR/frames.csv (one row per image set: ok / skipped / failed
with the reason, ms per stage, coverage, ring method). Image sets and sweeps are paired as the
fusion nodelet pairs them; the LiDAR -> camera transform is read from /tf_static and /tf.

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
                      read, so the pairing is the same as in a whole run)
  --lead-in S         default 3
  --disparity         also DIR/disparity/<stamp>.png (uint16, px * 256, 0 = none)
  --confidence        also DIR/confidence/<stamp>.png (uint16, confidence * 65535)
  --cloud             also DIR/cloud/<stamp>.pcd (left optical frame, intensity = grey value)
  --out-bag FILE      the nodelet's output topics (under --ns, default /fusion), stamped as
                      their inputs, at the left image's bag time
  --frames-csv FILE   write the rows there instead of DIR/frames.csv
  --resume            keep the sets whose depth PNG exists (and their rows)
  --help              this text
Remaps (the nodelet's input names): left/image_rect_color:=TOPIC, left/camera_info:=TOPIC,
right/image_rect_color:=TOPIC, right/camera_info:=TOPIC, velodyne_points:=TOPIC (defaults:
/stereo/..., /velodyne_points as written by kitti_to_bag); output names (depth/image_rect, ...)
for --out-bag.

Exit status: 0 when no set failed, 1 when any set failed (each is named) or on bad input (an
unreadable bag, a missing input topic), 2 on a bad command line.
)";

struct Options {
  std::vector<std::string> bags;
  std::string params, node_params, method, frames_csv;
  double start = -1, end = -1, lead_in = 3.0;
  bool resume = false, approximate_sync = false;
  lsf::BagTopics topics;
  lsf::OutputOptions outputs;
};

Options parseOptions(int argc, char** argv) {
  Options o;
  std::vector<const char*> rest = {argv[0]};
  for (int i = 1; i < argc; ++i) {  // --bag may repeat; NAME:=TOPIC are remaps
    const std::string a = argv[i];
    if (a == "--bag") {
      if (i + 1 >= argc) throw lsf::UsageError("--bag needs a file");
      o.bags.push_back(argv[++i]);
    } else if (a.find(":=") != std::string::npos && a.rfind("--", 0) != 0) {
      const std::string from = a.substr(0, a.find(":=")), to = a.substr(a.find(":=") + 2);
      if (to.empty()) throw lsf::UsageError("remap " + a + " has no topic");
      const std::map<std::string, std::string*> inputs = {
          {"left/image_rect_color", &o.topics.left_image},
          {"left/camera_info", &o.topics.left_info},
          {"right/image_rect_color", &o.topics.right_image},
          {"right/camera_info", &o.topics.right_info},
          {"velodyne_points", &o.topics.cloud}};
      const auto input = inputs.find(from);
      *(input != inputs.end() ? input->second : &o.outputs.remaps[from]) = to;
    } else {
      rest.push_back(argv[i]);
    }
  }
  const lsf::CommandLine cl(
      static_cast<int>(rest.size()), rest.data(),
      {"--out", "--params", "--node-params", "--method", "--start", "--end", "--lead-in",
       "--out-bag", "--ns", "--frames-csv"},
      {"--disparity", "--confidence", "--cloud", "--resume", "--approximate-sync", "--help"});
  if (cl.has("--help")) return Options();
  o.outputs.dir = cl.value("--out");
  if (o.bags.empty()) throw lsf::UsageError("--bag is required");
  if (o.outputs.dir.empty()) throw lsf::UsageError("--out is required");
  o.params = cl.value("--params");
  o.node_params = cl.value("--node-params");
  if (cl.has("--method")) {
    o.method = cl.choice("--method", "", {"fused_bi", "fused_bf", "pms", "lidar_bi", "lidar_bf"});
  }
  o.start = cl.doubleValue("--start", -1, 0, 1e9);
  o.end = cl.doubleValue("--end", -1, 0, 1e9);
  if (o.start >= 0 && o.end >= 0 && o.end <= o.start) throw lsf::UsageError("--end <= --start");
  o.lead_in = cl.doubleValue("--lead-in", 3.0, 0, 3600);
  o.outputs.out_bag = cl.value("--out-bag");
  o.outputs.ns = cl.value("--ns", "/fusion");
  o.outputs.disparity = cl.has("--disparity");
  o.outputs.confidence = cl.has("--confidence");
  o.outputs.cloud = cl.has("--cloud");
  o.frames_csv = cl.value("--frames-csv", (fs::path(o.outputs.dir) / "frames.csv").string());
  o.resume = cl.has("--resume");
  o.approximate_sync = cl.has("--approximate-sync");
  return o;
}

/// The node parameters: --node-params, then --approximate-sync.
lsf::NodeParams readNodeParams(const Options& o) {
  lsf::NodeParams p =
      o.node_params.empty() ? lsf::NodeParams() : lsf::readNodeParamsYaml(o.node_params);
  if (o.approximate_sync) p.approximate_sync = true;
  return p;
}

/// The ok rows of an earlier run (frames.csv, or the rows written before it was killed) by stamp,
/// for --resume.
std::map<std::string, std::string> earlierRows(const std::vector<std::string>& files) {
  std::map<std::string, std::string> rows;
  for (const auto& file : files) {
    std::ifstream in(file);
    std::string line;
    while (std::getline(in, line)) {
      const std::string stamp = line.substr(0, line.find(','));
      if (line.compare(stamp.size(), 4, ",ok,") == 0) rows.emplace(stamp, line + "\n");
    }
  }
  return rows;
}

class Runner {
 public:
  explicit Runner(const Options& o) : o_(o), node_params_(readNodeParams(o)) {
    if (!o.params.empty()) lsf::loadParamsYaml(o.params, params_);
    if (!o.method.empty()) params_.method = lsf::parseMethod(o.method);
    params_.validate();
    for (const auto& path : o.bags) {
      bags_.push_back(std::make_unique<rosbag::Bag>());
      try {
        bags_.back()->open(path, rosbag::bagmode::Read);
      } catch (const std::exception& e) {
        throw std::runtime_error("cannot read bag " + path + ": " + e.what() +
                                 " (truncated by an interrupted recording? `rosbag reindex` "
                                 "may recover it)");
      }
    }
  }

  int run();

 private:
  void checkTopics();
  void finishSet(lsf::SetOutcome& s, lsf::FusionPipeline& pipeline, lsf::OutputWriter& writer);
  /// Processes the decided sets; a matched set waits until the bag is read 1 s past its sweep
  /// (the /tf around the sweep stamp), unless `all`.
  void drain(bool all, lsf::FusionPipeline& pipeline, lsf::OutputWriter& writer,
             lsf::ProgressBar& progress);
  void writeRows() const;

  Options o_;
  lsf::NodeParams node_params_;
  lsf::FusionParams params_;
  std::vector<std::unique_ptr<rosbag::Bag>> bags_;
  std::unique_ptr<lsf::BagPairing> pairing_;
  ros::Time begin_, from_, to_;  ///< recording start; the sets reported are in [from_, to_)
  std::map<ros::Time, std::string> rows_;
  std::map<std::string, std::string> earlier_;
  std::vector<std::string> failed_;
  std::ofstream partial_;  ///< the ok rows so far (frames.csv.partial), for a resumed run
  int done_ = 0, ok_ = 0, skipped_ = 0;
};

void Runner::checkTopics() {
  rosbag::View all;
  for (const auto& bag : bags_) all.addQuery(*bag);
  std::set<std::string> present;
  for (const auto* c : all.getConnections()) present.insert(c->topic);
  std::string names;
  for (const auto& t : present) names += " " + t;
  const std::vector<std::pair<const char*, std::string>> needed = {
      {"left/image_rect_color", o_.topics.left_image},
      {"left/camera_info", o_.topics.left_info},
      {"right/image_rect_color", o_.topics.right_image},
      {"right/camera_info", o_.topics.right_info},
      {"velodyne_points", o_.topics.cloud}};
  std::string missing;
  for (const auto& [name, topic] : needed) {
    if (!present.count(topic)) missing += " " + topic + " (remap with " + name + ":=TOPIC)";
  }
  if (!missing.empty()) {
    throw std::runtime_error("the recording has no messages on" + missing +
                             "; its topics:" + (names.empty() ? " none" : names));
  }
  if (!present.count("/tf_static") && !present.count("/tf")) {
    throw std::runtime_error(
        "the recording has no /tf_static or /tf: no LiDAR -> camera "
        "transform; its topics:" +
        names);
  }
  begin_ = all.getBeginTime();
  from_ = o_.start >= 0 ? begin_ + ros::Duration(o_.start) : ros::TIME_MIN;
  to_ = o_.end >= 0 ? begin_ + ros::Duration(o_.end) : ros::TIME_MAX;
}

void Runner::finishSet(lsf::SetOutcome& s, lsf::FusionPipeline& pipeline,
                       lsf::OutputWriter& writer) {
  if (s.receipt < from_ || s.receipt >= to_) return;  // lead-in / lead-out: another run's set
  ++done_;
  const std::string name = lsf::stampName(s.stamp);
  if (!s.match) {
    ++skipped_;
    rows_[s.stamp] = lsf::notOkRow(s.stamp, "skipped", s.skip_reason);
    return;
  }
  if (o_.resume && fs::exists(writer.depthPath(s.stamp))) {
    ++ok_;
    const auto it = earlier_.find(name);
    rows_[s.stamp] = it != earlier_.end() ? it->second : lsf::notOkRow(s.stamp, "ok", "resumed");
    return;
  }
  const lsf::InputMatch& match = *s.match;
  const std::string& camera_frame = match.images.left->header.frame_id;
  const std::string& lidar_frame = match.sweep->header.frame_id;
  std::string reason;
  try {
    Eigen::Isometry3d T;
    const ros::Time at =
        lsf::extrinsicsStamp(node_params_.fixed_frame, match.sweep_stamp, match.image_stamp);
    try {
      T = tf2::transformToEigen(pairing_->tf().lookupTransform(camera_frame, lidar_frame, at));
    } catch (const tf2::TransformException& e) {
      throw std::runtime_error("no transform from '" + lidar_frame + "' (" + o_.topics.cloud +
                               ") to '" + camera_frame + "' (" + o_.topics.left_image +
                               ") at the " +
                               (node_params_.fixed_frame.empty() ? "sweep" : "image") + " stamp " +
                               lsf::stampName(at) + " in /tf_static or /tf: " + e.what());
    }
    const lsf::FusedSet set = lsf::fuseSet(match, T, pipeline, node_params_, pairing_->tf());
    if (!set.report.motion_failure.empty()) {
      std::cerr << "\nbag_runner: warning: image set " << name
                << " processed without ego-motion compensation (~motion_failure: uncompensated): "
                << set.report.motion_failure << "\n";
    }
    writer.write(match, s.receipt, set, params_);
    rows_[s.stamp] = lsf::okRow(s.stamp, match, set, lsf::methodName(params_.method));
    partial_ << rows_[s.stamp] << std::flush;  // for --resume after a kill
    ++ok_;
    return;
  } catch (const std::exception& e) {
    reason = e.what();
  }
  failed_.push_back(name);
  rows_[s.stamp] = lsf::notOkRow(s.stamp, "failed", reason);
  std::cerr << "\nbag_runner: error: image set " << name << " failed: " << reason << "\n";
}

void Runner::drain(bool all, lsf::FusionPipeline& pipeline, lsf::OutputWriter& writer,
                   lsf::ProgressBar& progress) {
  constexpr double kTfLookahead = 1.0;  ///< [s] of bag read past a sweep before its TF lookup
  auto& decided = pairing_->decided();
  while (!decided.empty()) {
    lsf::SetOutcome& s = decided.front();
    if (!all && s.match && pairing_->now() < s.match->sweep_stamp + ros::Duration(kTfLookahead)) {
      break;
    }
    const int before = done_;
    finishSet(s, pipeline, writer);
    if (done_ != before) progress.update(done_, lsf::stampName(s.stamp));
    decided.pop_front();
  }
}

void Runner::writeRows() const {
  std::string text = lsf::framesCsvHeader();
  for (const auto& kv : rows_) text += kv.second;
  lsf::writeFileAtomically(o_.frames_csv, text);
}

int Runner::run() {
  checkTopics();
  fs::create_directories(o_.outputs.dir);
  const std::string partial = o_.frames_csv + ".partial";
  if (o_.resume) {
    earlier_ =
        earlierRows({partial, o_.frames_csv, (fs::path(o_.outputs.dir) / "frames.csv").string()});
  }
  partial_.open(partial, std::ios::app);
  pairing_ = std::make_unique<lsf::BagPairing>(node_params_, o_.topics);
  {
    // /tf_static of the whole recording: recorded once at its start, needed by every time range.
    rosbag::View statics;
    for (const auto& bag : bags_) statics.addQuery(*bag, rosbag::TopicQuery("/tf_static"));
    for (const rosbag::MessageInstance& m : statics) pairing_->addTf(m, true);
  }
  // Read from --lead-in before the range, and on past its end until its last sets are decided.
  const ros::Time read_from =
      from_ == ros::TIME_MIN
          ? ros::TIME_MIN
          : std::max(begin_, from_ - ros::Duration(std::min(o_.lead_in, (from_ - begin_).toSec())));
  const ros::Time read_to =
      to_ == ros::TIME_MAX
          ? ros::TIME_MAX
          : to_ + ros::Duration(node_params_.max_sweep_wait + node_params_.max_time_offset + 2.0);
  rosbag::View count, view;
  const std::vector<std::string> inputs = {o_.topics.left_image,  o_.topics.left_info,
                                           o_.topics.right_image, o_.topics.right_info,
                                           o_.topics.cloud,       "/tf"};
  for (const auto& bag : bags_) {
    // View ends are inclusive; the range is [from_, to_).
    count.addQuery(*bag, rosbag::TopicQuery(o_.topics.left_image), from_,
                   to_ == ros::TIME_MAX ? to_ : to_ - ros::Duration(0, 1));
    view.addQuery(*bag, rosbag::TopicQuery(inputs), read_from, read_to);
  }
  const int total = static_cast<int>(count.size());
  std::cerr << "bag_runner: " << total << " image sets on " << o_.topics.left_image << ", method "
            << lsf::methodName(params_.method) << ", "
            << (node_params_.approximate_sync ? "approximate" : "exact") << " image sync\n";

  lsf::FusionPipeline pipeline(params_);
  lsf::OutputWriter writer(o_.outputs, node_params_);
  lsf::ProgressBar progress(std::cerr, total, ::isatty(2) != 0);
  std::string read_error;
  try {
    for (const rosbag::MessageInstance& m : view) {
      pairing_->add(m);
      drain(false, pipeline, writer, progress);
    }
  } catch (const std::exception& e) {  // a damaged chunk, a message of the wrong type
    read_error = "cannot read the recording after bag time " + lsf::stampName(pairing_->now()) +
                 ": " + e.what();
  }
  pairing_->finish();
  drain(true, pipeline, writer, progress);
  progress.finish();
  writer.close();
  writeRows();
  partial_.close();
  fs::remove(partial);

  std::cout << "bag_runner: " << done_ << " image sets: " << ok_ << " ok, " << skipped_
            << " skipped, " << failed_.size() << " failed; wrote " << o_.frames_csv << "\n";
  if (!failed_.empty()) {
    std::string names;
    for (const auto& n : failed_) names += " " + n;
    std::cerr << "bag_runner: " << failed_.size() << " image sets failed:" << names << "\n";
  }
  if (!read_error.empty()) std::cerr << "bag_runner: error: " << read_error << "\n";
  return failed_.empty() && read_error.empty() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
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
    return Runner(options).run();
  } catch (const std::exception& e) {
    std::cerr << "\nbag_runner: error: " << e.what() << "\n";
    return 1;
  }
}
