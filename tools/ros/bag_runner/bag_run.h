// One run of bag_runner over a recording (see bag_runner.cpp for the command line): the inputs
// opened and checked (bag_inputs.h), the output folder checked against the inputs, proven
// writable and matched with its manifest (bag_files.h, bag_manifest.h), then every image set
// paired (BagPairing), fused and written (bag_outputs.h), and frames.csv.
#pragma once

#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <rosbag/bag.h>

#include "bag_inputs.h"
#include "bag_manifest.h"
#include "bag_outputs.h"
#include "bag_pairing.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/io/progress.h"

namespace lidar_stereo_fusion {

struct BagRunOptions {
  std::vector<std::string> bags;
  std::string params, node_params, method, frames_csv;
  double start = -1, end = -1, lead_in = 3.0;
  bool resume = false, approximate_sync = false, force = false;
  bool prepare = false;      ///< check and prepare the output folder, then stop (lsf_batch)
  bool allow_empty = false;  ///< an empty time window is no error (lsf_batch's chunks)
  BagTopics topics;
  OutputOptions outputs;
};

class BagRun {
 public:
  /// Reads the parameters (--params, --method, --node-params); throws naming a bad one.
  explicit BagRun(const BagRunOptions& options);
  /// The whole run; the exit status (0: no set failed, 1: a set failed or the recording could
  /// not be read to its end). Bad input or an unusable output folder throws before any set.
  int run();

 private:
  void openInputs();
  /// Outputs against inputs, folders writable; the folders written.
  std::vector<std::string> checkPaths() const;
  /// The manifest: equal, refused (naming what differs), or replaced with --force.
  void matchManifest();
  void prepareFolder();
  int process();
  void finishSet(SetOutcome& s, FusionPipeline& pipeline, OutputWriter& writer);
  /// Processes the decided sets; a matched set waits until the bag is read 1 s past its sweep
  /// (the /tf around the sweep stamp), unless `all`.
  void drain(bool all, FusionPipeline& pipeline, OutputWriter& writer, ProgressBar& progress);
  void printWarnings();
  void writeRows() const;
  int report(const std::string& read_error) const;

  BagRunOptions o_;
  NodeParams node_params_;
  FusionParams params_;
  std::vector<std::unique_ptr<rosbag::Bag>> bags_;
  BagTopics topics_;  ///< as read (an image topic may have become <topic>/compressed)
  TimeWindow window_;
  std::unique_ptr<BagPairing> pairing_;
  std::map<ros::Time, std::string> rows_;
  std::map<std::string, std::string> earlier_;
  std::vector<std::string> failed_;
  std::ofstream partial_;  ///< the ok rows so far (frames.csv.partial), for a resumed run
  int done_ = 0, ok_ = 0, skipped_ = 0;
};

}  // namespace lidar_stereo_fusion
