#include "bag_run.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <rosbag/view.h>
#include <tf2/exceptions.h>
#include <tf2_eigen/tf2_eigen.h>

#include "bag_files.h"
#include "lidar_stereo_fusion/io/params_yaml.h"
#include "lidar_stereo_fusion/io/process_memory.h"
#include "lidar_stereo_fusion/io/progress.h"
#include "lidar_stereo_fusion/ros/ego_motion.h"

namespace fs = std::filesystem;

namespace lidar_stereo_fusion {

namespace {

/// The node parameters: --node-params, then --approximate-sync.
NodeParams readNodeParams(const BagRunOptions& o) {
  NodeParams p = o.node_params.empty() ? NodeParams() : readNodeParamsYaml(o.node_params);
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

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string joined(const std::vector<std::string>& lines, const std::string& separator) {
  std::string out;
  for (const auto& l : lines) out += (out.empty() ? "" : separator) + l;
  return out;
}

}  // namespace

BagRun::BagRun(const BagRunOptions& options) : o_(options), node_params_(readNodeParams(options)) {
  if (!o_.params.empty()) loadParamsYaml(o_.params, params_);
  if (!o_.method.empty()) params_.method = parseMethod(o_.method);
  params_.validate();
}

void BagRun::openInputs() {
  for (const auto& path : o_.bags) bags_.push_back(openBag(path));
  std::vector<std::string> notes;
  topics_ = resolveTopics(bags_, o_.topics, &notes);
  for (const auto& note : notes) std::cerr << "bag_runner: " << note << "\n";
  window_ = timeWindow(bags_, topics_.left_image, o_.start, o_.end, o_.allow_empty || o_.prepare);
}

std::vector<std::string> BagRun::checkPaths() const {
  const fs::path dir(o_.outputs.dir);
  std::vector<LabelledPath> inputs, outputs = {{"--out folder", o_.outputs.dir},
                                               {"--frames-csv", o_.frames_csv},
                                               {"manifest", (dir / Manifest::kFileName).string()}};
  for (const auto& bag : o_.bags) inputs.push_back({"input bag", bag});
  if (!o_.params.empty()) inputs.push_back({"--params file", o_.params});
  if (!o_.node_params.empty()) inputs.push_back({"--node-params file", o_.node_params});
  if (!o_.outputs.out_bag.empty()) outputs.push_back({"--out-bag", o_.outputs.out_bag});
  std::vector<std::string> folders = {o_.outputs.dir,
                                      fs::absolute(o_.frames_csv).parent_path().string()};
  for (const auto& [asked, sub] :
       {std::pair{o_.outputs.disparity, "disparity"},
        std::pair{o_.outputs.confidence, "confidence"}, std::pair{o_.outputs.cloud, "cloud"}}) {
    if (!asked) continue;
    outputs.push_back({std::string("--") + sub + " folder", (dir / sub).string()});
    folders.push_back((dir / sub).string());
  }
  if (!o_.outputs.out_bag.empty()) {
    folders.push_back(fs::absolute(o_.outputs.out_bag).parent_path().string());
  }
  checkOutputsAgainstInputs(outputs, inputs);  // before anything is opened for writing
  for (const auto& folder : folders) requireWritableFolder(folder, "output");
  return folders;
}

void BagRun::matchManifest() {
  const Manifest manifest =
      runManifest(packageVersion(), o_.bags, topics_, params_, node_params_, o_.lead_in);
  const std::string path = (fs::path(o_.outputs.dir) / Manifest::kFileName).string();
  const bool has_manifest = fs::exists(path);
  const std::string start_over =
      ". Use --force to remove those outputs and start over, or choose another --out";
  if (!o_.force && has_manifest) {
    const auto differences = manifest.differences(Manifest::parse(readText(path)));
    if (!differences.empty()) {
      throw std::runtime_error(o_.outputs.dir + " holds the outputs of another run (" + path +
                               "); what differs: " + joined(differences, "; ") + start_over);
    }
  } else if (!o_.force && holdsOutputs(o_.outputs.dir)) {
    throw std::runtime_error(o_.outputs.dir +
                             " holds depth PNGs or frames.csv but no manifest.txt (made by an "
                             "older bag_runner or another tool), so what made them is unknown" +
                             start_over);
  } else if (o_.force && (has_manifest || holdsOutputs(o_.outputs.dir))) {
    const int removed = removeEarlierOutputs(o_.outputs.dir);
    std::cerr << "bag_runner: --force: removed " << removed << " files of the earlier run in "
              << o_.outputs.dir << "\n";
  }
  if (o_.force || !has_manifest) writeFileAtomically(path, manifest.text());
}

void BagRun::prepareFolder() {
  const std::vector<std::string> folders = checkPaths();
  matchManifest();
  int stale = 0;
  for (const auto& folder : folders) stale += removeStaleTemps(folder, o_.prepare);
  if (stale > 0) {
    std::cerr << "bag_runner: removed " << stale << " temporary files of an interrupted run\n";
  }
}

int BagRun::run() {
  openInputs();
  prepareFolder();
  if (o_.prepare) {
    std::cout << "bag_runner: " << o_.outputs.dir << " ready (" << window_.sets << " image sets)\n";
    return 0;
  }
  return process();
}

void BagRun::finishSet(SetOutcome& s, FusionPipeline& pipeline, OutputWriter& writer) {
  if (s.receipt < window_.from || s.receipt >= window_.to) return;  // another run's set
  ++done_;
  const std::string name = stampName(s.stamp);
  if (!s.match) {
    ++skipped_;
    rows_[s.stamp] = notOkRow(s.stamp, "skipped", s.skip_reason);
    return;
  }
  if (o_.resume && writer.complete(s.stamp)) {
    ++ok_;
    const auto it = earlier_.find(name);
    rows_[s.stamp] = it != earlier_.end() ? it->second : notOkRow(s.stamp, "ok", "resumed");
    return;
  }
  const InputMatch& match = *s.match;
  const std::string& camera_frame = match.images.left->header.frame_id;
  const std::string& lidar_frame = match.sweep->header.frame_id;
  try {
    const ros::Time at =
        extrinsicsStamp(node_params_.fixed_frame, match.sweep_stamp, match.image_stamp);
    Eigen::Isometry3d T;
    try {
      T = tf2::transformToEigen(pairing_->tf().lookupTransform(camera_frame, lidar_frame, at));
    } catch (const tf2::TransformException& e) {
      throw std::runtime_error("no transform from '" + lidar_frame + "' (" + topics_.cloud +
                               ") to '" + camera_frame + "' (" + topics_.left_image + ") at the " +
                               (node_params_.fixed_frame.empty() ? "sweep" : "image") + " stamp " +
                               stampName(at) + " in /tf_static or /tf: " + e.what());
    }
    const FusedSet set = fuseSet(match, T, pipeline, node_params_, pairing_->tf());
    if (!set.report.motion_failure.empty()) {
      std::cerr << "\nbag_runner: warning: image set " << name
                << " processed without ego-motion compensation (~motion_failure: uncompensated): "
                << set.report.motion_failure << "\n";
    }
    writer.write(match, s.receipt, set, params_);
    rows_[s.stamp] = okRow(s.stamp, match, set, methodName(params_.method));
    partial_ << rows_[s.stamp] << std::flush;  // for --resume after a kill
    ++ok_;
  } catch (const std::exception& e) {
    failed_.push_back(name);
    rows_[s.stamp] = notOkRow(s.stamp, "failed", e.what());
    std::cerr << "\nbag_runner: error: image set " << name << " failed: " << e.what() << "\n";
  }
}

void BagRun::drain(bool all, FusionPipeline& pipeline, OutputWriter& writer,
                   ProgressBar& progress) {
  constexpr double kTfLookahead = 1.0;  ///< [s] of bag read past a sweep before its TF lookup
  auto& decided = pairing_->decided();
  while (!decided.empty()) {
    SetOutcome& s = decided.front();
    if (!all && s.match && pairing_->now() < s.match->sweep_stamp + ros::Duration(kTfLookahead)) {
      break;
    }
    const int before = done_;
    finishSet(s, pipeline, writer);
    if (done_ != before) progress.update(done_, stampName(s.stamp));
    decided.pop_front();
  }
}

void BagRun::printWarnings() {
  for (const auto& w : pairing_->takeWarnings())
    std::cerr << "\nbag_runner: warning: " << w << "\n";
}

void BagRun::writeRows() const {
  std::string text = framesCsvHeader();
  for (const auto& kv : rows_) text += kv.second;
  writeFileAtomically(o_.frames_csv, text);
}

int BagRun::process() {
  const std::string partial = o_.frames_csv + ".partial";
  if (o_.resume) {
    earlier_ =
        earlierRows({partial, o_.frames_csv, (fs::path(o_.outputs.dir) / "frames.csv").string()});
  }
  partial_.open(partial, std::ios::app);
  pairing_ = std::make_unique<BagPairing>(node_params_, topics_);
  {
    // /tf_static of the whole recording: recorded once at its start, needed by every time range.
    rosbag::View statics;
    for (const auto& bag : bags_) statics.addQuery(*bag, rosbag::TopicQuery("/tf_static"));
    for (const rosbag::MessageInstance& m : statics) pairing_->addTf(m, true);
  }
  // Read from --lead-in before the window, and on past its end until its last sets are decided.
  const ros::Time read_from =
      window_.from == ros::TIME_MIN
          ? ros::TIME_MIN
          : std::max(window_.begin,
                     window_.from - ros::Duration(std::min(
                                        o_.lead_in, (window_.from - window_.begin).toSec())));
  const ros::Time read_to = window_.to == ros::TIME_MAX
                                ? ros::TIME_MAX
                                : window_.to + ros::Duration(node_params_.max_sweep_wait +
                                                             node_params_.max_time_offset + 2.0);
  rosbag::View view;
  const std::vector<std::string> inputs = {topics_.left_image,  topics_.left_info,
                                           topics_.right_image, topics_.right_info,
                                           topics_.cloud,       "/tf"};
  for (const auto& bag : bags_) view.addQuery(*bag, rosbag::TopicQuery(inputs), read_from, read_to);
  std::cerr << "bag_runner: " << window_.sets << " image sets on " << topics_.left_image
            << ", method " << methodName(params_.method) << ", "
            << (node_params_.approximate_sync ? "approximate" : "exact") << " image sync\n";

  std::string memory_problem;  // as the node: frames reuse the last frame's pages
  if (node_params_.keep_freed_memory && !keepFreedMemory(&memory_problem)) {
    std::cerr << "bag_runner: keep_freed_memory: " << memory_problem << "\n";
  }
  FusionPipeline pipeline(params_);
  OutputWriter writer(o_.outputs, node_params_);
  ProgressBar progress(std::cerr, window_.sets, ::isatty(2) != 0);
  std::string read_error;
  try {
    for (const rosbag::MessageInstance& m : view) {
      pairing_->add(m);
      printWarnings();
      drain(false, pipeline, writer, progress);
    }
  } catch (const std::exception& e) {  // a damaged chunk, a message of the wrong type
    read_error =
        "cannot read the recording after bag time " + stampName(pairing_->now()) + ": " + e.what();
  }
  pairing_->finish();
  drain(true, pipeline, writer, progress);
  progress.finish();
  writer.close();
  writeRows();
  partial_.close();
  fs::remove(partial);
  return report(read_error);
}

int BagRun::report(const std::string& read_error) const {
  std::cout << "bag_runner: " << done_ << " image sets: " << ok_ << " ok, " << skipped_
            << " skipped, " << failed_.size() << " failed; wrote " << o_.frames_csv << "\n";
  if (!failed_.empty()) {
    std::cerr << "bag_runner: " << failed_.size() << " image sets failed: " << joined(failed_, " ")
              << "\n";
  }
  if (!read_error.empty()) std::cerr << "bag_runner: error: " << read_error << "\n";
  return failed_.empty() && read_error.empty() ? 0 : 1;
}

}  // namespace lidar_stereo_fusion
