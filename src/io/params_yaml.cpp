// FusionParams <-> YAML. Reading uses OpenCV FileStorage; writing emits plain YAML (no OpenCV
// "%YAML:1.0" directive) so that rosparam can load the same file.
//
// The keys are the names of io/param_table.h, at the top level (one name per parameter, as in
// rosparam and dynamic_reconfigure). The previous layout, the same names in sections
// (`patchmatch: {window_radius: 5}`), is still read.
#include "lidar_stereo_fusion/io/params_yaml.h"

#include "lidar_stereo_fusion/io/param_table.h"
#include "lidar_stereo_fusion/io/text_file.h"

#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace lidar_stereo_fusion {
namespace {

// ---- Reading --------------------------------------------------------------------------------

/// A string scalar without a trailing "# comment": OpenCV's YAML reader keeps comments after
/// unquoted string values ("slanted: true  # note" reads as "true  # note").
std::string scalarString(const cv::FileNode& node) {
  std::string s = node.string();
  for (size_t i = 1; i < s.size(); ++i) {
    if (s[i] == '#' && (s[i - 1] == ' ' || s[i - 1] == '\t')) {
      s.resize(i);
      break;
    }
  }
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.pop_back();
  return s;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

/// Reads the values present in the file, with errors naming file and key. A key is looked up at
/// the top level and, as the deprecated layout, in its group's section.
class FieldReader {
 public:
  FieldReader(const cv::FileNode& root, std::string path) : root_(root), path_(std::move(path)) {}

  template <class T>
  void operator()(const ParamName& n, T& value) {
    const cv::FileNode top = root_[n.name];
    cv::FileNode grouped;
    if (*n.group != '\0') {
      const cv::FileNode section = root_[n.group];
      if (!section.empty() && section.isMap()) grouped = section[n.name];
    }
    if (!top.empty() && !grouped.empty()) {
      fail(n.name, std::string("is given twice (top level and in section '") + n.group + "')");
    }
    const cv::FileNode& node = top.empty() ? grouped : top;
    if (!node.empty()) read(node, n.name, value);
  }

 private:
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw std::runtime_error("params YAML " + path_ + ": key '" + key + "' " + what);
  }

  void read(const cv::FileNode& node, const std::string& key, Method& value) const {
    if (!node.isString()) fail(key, "must be a name");
    try {
      value = parseMethod(scalarString(node));
    } catch (const std::invalid_argument& e) {
      fail(key, e.what());
    }
  }

  void read(const cv::FileNode& node, const std::string& key, double& value) const {
    if (!node.isReal() && !node.isInt()) fail(key, "must be a number");
    value = static_cast<double>(node);
    if (!std::isfinite(value)) fail(key, "must be finite");
  }

  void read(const cv::FileNode& node, const std::string& key, int& value) const {
    if (!node.isInt()) fail(key, "must be an integer");
    value = static_cast<int>(node);
    // Checked here too (not only in validate()): a thread count beyond this crashes libgomp.
    if (key == "num_threads" && (value < 0 || value > 256)) fail(key, "must be in [0, 256]");
  }

  void read(const cv::FileNode& node, const std::string& key, bool& value) const {
    if (node.isInt()) {
      const int v = static_cast<int>(node);
      if (v != 0 && v != 1) fail(key, "must be true or false");
      value = v == 1;
      return;
    }
    const std::string s = node.isString() ? lower(scalarString(node)) : std::string();
    if (s == "true") {
      value = true;
    } else if (s == "false") {
      value = false;
    } else {
      fail(key, "must be true or false");
    }
  }

  void read(const cv::FileNode& node, const std::string& key, uint64_t& value) const {
    if (node.isInt()) {
      const int v = static_cast<int>(node);
      // OpenCV reads integers as int: 3000000000 arrives here wrapped to a negative number.
      if (v < 0) fail(key, "must be >= 0; values above 2147483647 must be quoted (\"3000000000\")");
      value = static_cast<uint64_t>(v);
      return;
    }
    // Values beyond int32 have to be quoted (FileStorage has no 64-bit integers).
    const std::string s = node.isString() ? scalarString(node) : std::string();
    if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos) {
      fail(key, "must be a non-negative integer");
    }
    try {
      value = std::stoull(s);
    } catch (const std::exception&) {
      fail(key, "does not fit in 64 bits");
    }
  }

  cv::FileNode root_;
  std::string path_;
};

/// Throws on a key that is neither a parameter nor a (deprecated) section holding only the
/// parameters of its group.
void rejectUnknownKeys(const cv::FileNode& root, const std::string& path) {
  std::set<std::string> names;
  std::map<std::string, std::set<std::string>> groups;
  for (const ParamInfo& p : paramTable()) {
    names.insert(p.name);
    if (!p.group.empty()) groups[p.group].insert(p.name);
  }
  const auto list = [](const std::set<std::string>& keys) {
    std::string out;
    for (const std::string& k : keys) out += (out.empty() ? "" : ", ") + k;
    return out;
  };
  for (const cv::FileNode& node : root) {
    const std::string key = node.name();
    if (names.count(key)) continue;
    const auto group = groups.find(key);
    if (group == groups.end()) {
      throw std::runtime_error("params YAML " + path + ": unknown key '" + key +
                               "' (valid: " + list(names) + ")");
    }
    if (!node.isMap()) {
      throw std::runtime_error("params YAML " + path + ": '" + key + "' must be a map");
    }
    for (const cv::FileNode& field : node) {
      if (!group->second.count(field.name())) {
        throw std::runtime_error("params YAML " + path + " section '" + key + "': unknown key '" +
                                 field.name() + "' (valid: " + list(group->second) + ")");
      }
    }
  }
}

/// OpenCV's YAML reader needs a "%YAML" directive; rosparam files have none.
std::string withYamlDirective(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && text.compare(first, 5, "%YAML") == 0) return text;
  if (first != std::string::npos && text.compare(first, 3, "---") == 0) return "%YAML:1.0\n" + text;
  return "%YAML:1.0\n---\n" + text;
}

// ---- Writing --------------------------------------------------------------------------------

class FieldWriter {
 public:
  explicit FieldWriter(std::ostream& out) : out_(out) {}
  void operator()(const ParamName& n, Method v) { line(n, methodName(v)); }
  void operator()(const ParamName& n, double v) { line(n, formatParamDouble(v)); }
  void operator()(const ParamName& n, int v) { line(n, std::to_string(v)); }
  void operator()(const ParamName& n, bool v) { line(n, v ? "true" : "false"); }
  void operator()(const ParamName& n, uint64_t v) {
    const bool fits = v <= static_cast<uint64_t>(std::numeric_limits<int>::max());
    line(n, fits ? std::to_string(v) : "\"" + std::to_string(v) + "\"");
  }

 private:
  void line(const ParamName& n, const std::string& value) {
    if (group_ != n.group && *n.group != '\0') out_ << "# " << n.group << "\n";
    group_ = n.group;
    out_ << n.name << ": " << value << "\n";
  }
  std::ostream& out_;
  std::string group_;
};

}  // namespace

cv::FileStorage openYaml(const std::string& path) {
  const std::string raw = readTextFile(path, "params YAML");
  requireTextFile(raw, path, "params YAML");
  requireYamlMarkersAlone(raw, path, "params YAML");
  const std::string text = withYamlDirective(raw);
  cv::FileStorage fs;
  try {
    fs.open(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("params YAML " + path + ": not valid YAML (" + e.what() + ")");
  }
  if (!fs.isOpened()) throw std::runtime_error("params YAML " + path + ": not valid YAML");
  return fs;
}

void loadParamsYaml(const std::string& path, FusionParams& params) {
  cv::FileStorage fs = openYaml(path);
  const cv::FileNode root = fs.root();
  FusionParams loaded = params;
  if (!root.empty() && !root.isNone()) {
    if (!root.isMap()) throw std::runtime_error("params YAML " + path + ": top level is not a map");
    rejectUnknownKeys(root, path);
    visitParamTable(loaded, FieldReader(root, path));
  }
  try {
    loaded.validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("params YAML " + path + ": invalid value: " + e.what());
  }
  params = loaded;
}

void saveParamsYaml(const std::string& path, const FusionParams& params) {
  std::ostringstream out;
  out << "# lidar_stereo_fusion parameters (every field; names: io/param_table.h)\n";
  visitParamTable(params, FieldWriter(out));
  std::ofstream file(path);
  if (!file) throw std::runtime_error("params YAML: cannot create " + path);
  file << out.str();
  if (!file) throw std::runtime_error("params YAML: cannot write " + path);
}

}  // namespace lidar_stereo_fusion
