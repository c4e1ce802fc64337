#include "bag_manifest.h"

#include <sys/stat.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "lidar_stereo_fusion/core/param_spec.h"
#include "lidar_stereo_fusion/io/param_table.h"

#ifndef LSF_PACKAGE_VERSION
#define LSF_PACKAGE_VERSION "unknown"
#endif

namespace fs = std::filesystem;

namespace lidar_stereo_fusion {

namespace {

constexpr std::size_t kHashedBytes = 1 << 20;  ///< [B] hashed at each end of a file

/// FNV-1a, 64 bit: an identity check, not a defence against forgery (no crypto library needed).
void fnv1a(const char* data, std::size_t n, uint64_t& h) {
  for (std::size_t i = 0; i < n; ++i) {
    h ^= static_cast<unsigned char>(data[i]);
    h *= 1099511628211ull;
  }
}

std::string hex(uint64_t v) {
  char text[20];
  std::snprintf(text, sizeof(text), "%016" PRIx64, v);
  return text;
}

/// Node parameters that do not change what bag_runner writes (the live node's rate, timing,
/// monitoring and colour scale). Every other row is in the manifest, new rows included.
const std::set<std::string>& ignoredNodeParams() {
  static const std::set<std::string> kIgnored = {"max_rate",
                                                 "fresh_wait",
                                                 "tf_timeout",
                                                 "depth_color_max",
                                                 "input_timeout",
                                                 "log_throttle_period",
                                                 "worker_nice",
                                                 "keep_freed_memory",
                                                 "diagnostics/min_rate",
                                                 "diagnostics/max_rate",
                                                 "diagnostics/max_latency"};
  return kIgnored;
}

}  // namespace

void Manifest::set(const std::string& key, const std::string& value) {
  for (auto& kv : entries_) {
    if (kv.first == key) {
      kv.second = value;
      return;
    }
  }
  entries_.emplace_back(key, value);
}

std::string Manifest::get(const std::string& key) const {
  for (const auto& kv : entries_) {
    if (kv.first == key) return kv.second;
  }
  return "";
}

std::string Manifest::text() const {
  std::string out =
      "# bag_runner: what made the outputs in this folder (a run with other inputs or parameters "
      "refuses; --force starts over)\n";
  for (const auto& [key, value] : entries_) out += key + ": " + value + "\n";
  return out;
}

Manifest Manifest::parse(const std::string& text) {
  Manifest m;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const auto colon = line.find(": ");
    if (line.empty() || line[0] == '#' || colon == std::string::npos) continue;
    m.set(line.substr(0, colon), line.substr(colon + 2));
  }
  return m;
}

std::vector<std::string> Manifest::differences(const Manifest& earlier) const {
  std::vector<std::string> out;
  std::vector<std::string> keys;
  for (const auto& kv : earlier.entries_) keys.push_back(kv.first);
  for (const auto& kv : entries_) {
    if (std::find(keys.begin(), keys.end(), kv.first) == keys.end()) keys.push_back(kv.first);
  }
  for (const auto& key : keys) {
    const bool path = key.size() > 5 && key.compare(key.size() - 5, 5, ".path") == 0;
    const std::string before = earlier.get(key), now = get(key);
    if (path || before == now) continue;
    out.push_back(key + ": " + (before.empty() ? "(none)" : before) + " -> " +
                  (now.empty() ? "(none)" : now));
  }
  return out;
}

FileIdentity fileIdentity(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw std::runtime_error("cannot read " + path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  const auto size = static_cast<uint64_t>(st.st_size);
  uint64_t h = 14695981039346656037ull;
  std::string buffer(static_cast<std::size_t>(std::min<uint64_t>(size, kHashedBytes)), '\0');
  in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  fnv1a(buffer.data(), static_cast<std::size_t>(in.gcount()), h);
  if (size > kHashedBytes) {  // the end: a bag's index (connection and chunk records)
    const uint64_t tail = std::min<uint64_t>(size - kHashedBytes, kHashedBytes);
    in.clear();
    in.seekg(static_cast<std::streamoff>(size - tail));
    buffer.assign(static_cast<std::size_t>(tail), '\0');
    in.read(buffer.data(), static_cast<std::streamsize>(tail));
    fnv1a(buffer.data(), static_cast<std::size_t>(in.gcount()), h);
  }
  char when[64];
  std::tm utc{};
  gmtime_r(&st.st_mtim.tv_sec, &utc);
  const std::size_t n = std::strftime(when, sizeof(when), "%Y-%m-%d %H:%M:%S", &utc);
  std::snprintf(when + n, sizeof(when) - n, ".%09ld UTC", static_cast<long>(st.st_mtim.tv_nsec));
  return {std::to_string(size), when, hex(h)};
}

Manifest runManifest(const std::string& package_version, const std::vector<std::string>& bags,
                     const BagTopics& topics, const FusionParams& params,
                     const NodeParams& node_params, double lead_in) {
  Manifest m;
  m.set("package_version", package_version);
  m.set("bags", std::to_string(bags.size()));
  for (std::size_t i = 0; i < bags.size(); ++i) {
    const std::string key = "bag" + std::to_string(i + 1);
    const FileIdentity id = fileIdentity(bags[i]);
    std::error_code ec;
    m.set(key + ".path", fs::absolute(bags[i], ec).lexically_normal().string());
    m.set(key + ".size", id.size);
    m.set(key + ".mtime", id.mtime);
    m.set(key + ".hash", id.hash);
  }
  m.set("topic.left_image", topics.left_image);
  m.set("topic.left_info", topics.left_info);
  m.set("topic.right_image", topics.right_image);
  m.set("topic.right_info", topics.right_info);
  m.set("topic.cloud", topics.cloud);
  std::vector<ParamInfo> rows;
  visitParamTable(params, ParamLister{rows});
  for (const ParamInfo& r : rows) {
    if (r.name == "num_threads") continue;  // results do not depend on it
    m.set("param." + (r.group.empty() ? "" : r.group + ".") + r.name, r.default_value);
  }
  rows.clear();
  visitParams(node_params, ParamLister{rows});
  for (const ParamInfo& r : rows) {
    if (!ignoredNodeParams().count(r.name)) m.set("node." + r.name, r.default_value);
  }
  m.set("lead_in", formatParamDouble(lead_in));
  return m;
}

std::string packageVersion() { return LSF_PACKAGE_VERSION; }

}  // namespace lidar_stereo_fusion
