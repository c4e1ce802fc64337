// What made the files of a bag_runner output folder: DIR/manifest.txt, written before the first
// set and compared by every later run into DIR. A run whose manifest differs (another recording,
// method or parameter, another version of the package) refuses, saying what differs, unless
// --force, which removes the earlier outputs first; so a folder never mixes two runs and --resume
// only keeps depth made the way it would make it.
//
// The manifest: the package version; per input bag its size, modification time and a hash of its
// first and last MiB (a bag's header and first chunk, and its index); the input topics; every
// algorithm parameter but num_threads (results do not depend on it); the node parameters bag_runner
// uses (synchronisation, sweep matching, rings, ego-motion, output depth limit, cloud stride) and
// --lead-in. Bag paths are recorded but not compared (an archive may move).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "bag_pairing.h"
#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/ros/node_params.h"

namespace lidar_stereo_fusion {

class Manifest {
 public:
  static constexpr const char* kFileName = "manifest.txt";

  void set(const std::string& key, const std::string& value);
  /// The value of `key`, or "" when absent.
  std::string get(const std::string& key) const;
  /// "key: value" lines after a comment line.
  std::string text() const;
  /// Reads text(). Lines that are not "key: value" are ignored.
  static Manifest parse(const std::string& text);
  /// What differs from `earlier`, one "key: earlier -> this" per key (keys ending in ".path" are
  /// not compared; "(none)" for a missing value).
  std::vector<std::string> differences(const Manifest& earlier) const;

 private:
  std::vector<std::pair<std::string, std::string>> entries_;
};

/// The identity of an input file: size, modification time (UTC) and an FNV-1a 64 hash of its
/// first and last MiB. Throws std::runtime_error naming the path when it cannot be read.
struct FileIdentity {
  std::string size, mtime, hash;
};
FileIdentity fileIdentity(const std::string& path);

/// The manifest of a run: `package_version`, the bags (in order), topics, parameters, lead-in.
Manifest runManifest(const std::string& package_version, const std::vector<std::string>& bags,
                     const BagTopics& topics, const FusionParams& params,
                     const NodeParams& node_params, double lead_in);

/// The package version bag_runner was built from (package.xml).
std::string packageVersion();

}  // namespace lidar_stereo_fusion
