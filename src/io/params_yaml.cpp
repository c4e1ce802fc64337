// FusionParams <-> YAML. Reading uses OpenCV FileStorage; writing emits plain YAML (no OpenCV
// "%YAML:1.0" directive) so that rosparam can load the same file.
//
// The keys are the names of core/param_table.h, at the top level (one name per parameter, as in
// rosparam and dynamic_reconfigure). The previous layout, the same names in sections
// (`patchmatch: {window_radius: 5}`), is still read.
#include "lidar_stereo_fusion/io/params_yaml.h"

#include "lidar_stereo_fusion/io/param_docs.h"
#include "lidar_stereo_fusion/io/param_table.h"
#include "lidar_stereo_fusion/io/param_yaml_reader.h"
#include "lidar_stereo_fusion/io/text_file.h"

#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <string_view>

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

}  // namespace

void rejectUnknownParamKeys(const cv::FileNode& root, const std::string& path,
                            const std::vector<ParamInfo>& table, bool group_sections) {
  std::set<std::string> names;
  std::map<std::string, std::set<std::string>> groups;
  for (const ParamInfo& p : table) {
    const auto slash = p.name.find('/');
    if (slash != std::string::npos) {  // a section of its own (diagnostics/min_rate)
      groups[p.name.substr(0, slash)].insert(p.name.substr(slash + 1));
      continue;
    }
    names.insert(p.name);
    if (group_sections && !p.group.empty()) groups[p.group].insert(p.name);
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

namespace {

/// OpenCV's YAML reader needs a "%YAML" directive; rosparam files have none.
std::string withYamlDirective(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && text.compare(first, 5, "%YAML") == 0) return text;
  if (first != std::string::npos && text.compare(first, 3, "---") == 0) return "%YAML:1.0\n" + text;
  return "%YAML:1.0\n---\n" + text;
}

}  // namespace

// ---- YamlParamReader --------------------------------------------------------------------------

cv::FileNode YamlParamReader::find(const ParamSpec& spec) const {
  const std::string name = spec.name;
  const auto slash = name.find('/');
  if (slash != std::string::npos) {  // "diagnostics/min_rate": key min_rate of section diagnostics
    const cv::FileNode section = root_[name.substr(0, slash)];
    return section.isMap() ? section[name.substr(slash + 1)] : cv::FileNode();
  }
  const cv::FileNode top = root_[name];
  cv::FileNode grouped;
  if (group_sections_ && *spec.group != '\0') {
    const cv::FileNode section = root_[spec.group];
    if (!section.empty() && section.isMap()) grouped = section[name];
  }
  if (!top.empty() && !grouped.empty()) {
    fail(name, std::string("is given twice (top level and in section '") + spec.group + "')");
  }
  return top.empty() ? grouped : top;
}

void YamlParamReader::fail(const std::string& key, const std::string& what) const {
  throw std::runtime_error("params YAML " + path_ + ": key '" + key + "' " + what);
}

void YamlParamReader::read(const cv::FileNode& node, const ParamSpec& spec, Method& value) const {
  if (!node.isString()) fail(spec.name, "must be a name");
  try {
    value = parseMethod(scalarString(node));
  } catch (const std::invalid_argument& e) {
    fail(spec.name, e.what());
  }
}

void YamlParamReader::read(const cv::FileNode& node, const ParamSpec& spec, double& value) const {
  if (!node.isReal() && !node.isInt()) fail(spec.name, "must be a number");
  value = static_cast<double>(node);
  if (!std::isfinite(value)) fail(spec.name, "must be finite");
}

void YamlParamReader::read(const cv::FileNode& node, const ParamSpec& spec, int& value) const {
  if (!node.isInt()) fail(spec.name, "must be an integer");
  value = static_cast<int>(node);
  // Checked at once, not only in validate(): a thread count beyond the range crashes libgomp.
  if (std::string(spec.name) == "num_threads" && !rangeProblem(spec, value).empty()) {
    fail(spec.name, "must be " + spec.range.text());
  }
}

void YamlParamReader::read(const cv::FileNode& node, const ParamSpec& spec, bool& value) const {
  if (node.isInt()) {
    const int v = static_cast<int>(node);
    if (v != 0 && v != 1) fail(spec.name, "must be true or false");
    value = v == 1;
    return;
  }
  const std::string s = node.isString() ? lower(scalarString(node)) : std::string();
  if (s == "true") {
    value = true;
  } else if (s == "false") {
    value = false;
  } else {
    fail(spec.name, "must be true or false");
  }
}

void YamlParamReader::read(const cv::FileNode& node, const ParamSpec& spec, uint64_t& value) const {
  if (node.isInt()) {
    const int v = static_cast<int>(node);
    // OpenCV reads integers as int: 3000000000 arrives here wrapped to a negative number.
    if (v < 0) {
      fail(spec.name, "must be >= 0; values above 2147483647 must be quoted (\"3000000000\")");
    }
    value = static_cast<uint64_t>(v);
    return;
  }
  // Values beyond int32 have to be quoted (FileStorage has no 64-bit integers).
  const std::string s = node.isString() ? scalarString(node) : std::string();
  if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos) {
    fail(spec.name, "must be a non-negative integer");
  }
  try {
    value = std::stoull(s);
  } catch (const std::exception&) {
    fail(spec.name, "does not fit in 64 bits");
  }
}

void YamlParamReader::read(const cv::FileNode& node, const ParamSpec& spec,
                           std::string& value) const {
  if (!node.isString()) fail(spec.name, "must be text");
  const std::string word = scalarString(node);
  const std::string problem = choiceProblem(spec, word);
  if (!problem.empty()) fail(spec.name, problem.substr(std::string(spec.name).size() + 1));
  value = word;
}

namespace {

/// A parameter file holds names and values, in sections at most: every line but blank lines,
/// comments, a "%YAML" directive and document markers is "name: value" or "name:" (a section),
/// the name letters, digits and '_', indented by spaces and never less than the first name.
/// OpenCV 4.6's YAML parser never returns on some documents outside that form (found by
/// fuzz_params_yaml: a top-level sequence, "[m]" or "- ..." followed by more lines; " d:0", then
/// "x.", then "-"), so they are refused, naming the line, before it parses them.
void requireNameValueLines(const std::string& raw, const std::string& path) {
  std::size_t base = std::string_view::npos;  // the first name's indentation
  forEachLine(raw, [&](int number, std::string_view line) {
    const auto fail = [&](const std::string& what) {
      throw std::runtime_error("params YAML " + path + " line " + std::to_string(number) + ": " +
                               what);
    };
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string_view::npos || line[first] == '#' || (first == 0 && line[0] == '%') ||
        line.substr(first, 3) == "---" || line.substr(first, 3) == "...") {
      return;
    }
    if (base == std::string_view::npos && (line[first] == '[' || line[first] == '-')) {
      fail("top level is not a map (a sequence starts here)");
    }
    if (line.find('\t') < first) fail("a tab in the indentation (YAML indents with spaces)");
    std::size_t end = first;
    while (end < line.size() &&
           (std::isalnum(static_cast<unsigned char>(line[end])) != 0 || line[end] == '_')) {
      ++end;
    }
    if (end == first || end >= line.size() || line[end] != ':') {
      fail("not 'name: value' (a parameter file holds names and values, in sections at most)");
    }
    if (base == std::string_view::npos) base = first;
    if (first < base) {
      fail("indented by " + std::to_string(first) + " spaces, less than the first name's " +
           std::to_string(base));
    }
  });
}

}  // namespace

cv::FileStorage openYaml(const std::string& path) {
  const std::string raw = readTextFile(path, "params YAML");
  requireTextFile(raw, path, "params YAML");
  requireYamlMarkersAlone(raw, path, "params YAML");
  requireNameValueLines(raw, path);
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
    rejectUnknownParamKeys(root, path, paramTable());
    visitParamTable(loaded, YamlParamReader(root, path));
  }
  try {
    loaded.validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("params YAML " + path + ": invalid value: " + e.what());
  }
  params = loaded;
}

void saveParamsYaml(const std::string& path, const FusionParams& params) {
  std::vector<ParamInfo> rows;
  visitParamTable(params, ParamLister{rows});
  const std::string text = renderParamsYaml(
      rows, "lidar_stereo_fusion parameters (every field; the table: core/param_table.h)");
  std::ofstream file(path);
  if (!file) throw std::runtime_error("params YAML: cannot create " + path);
  file << text;
  if (!file) throw std::runtime_error("params YAML: cannot write " + path);
}

}  // namespace lidar_stereo_fusion
