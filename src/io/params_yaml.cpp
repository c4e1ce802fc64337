// FusionParams <-> YAML. Reading uses OpenCV FileStorage; writing emits plain YAML (no OpenCV
// "%YAML:1.0" directive) so that rosparam can load the same file.
//
// Every field is listed once, in the visit*() functions below; reading, the unknown-key check and
// writing all walk those lists, so a field added there is supported everywhere.
#include "lidar_stereo_fusion/io/params_yaml.h"

#include "lidar_stereo_fusion/io/text_file.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

namespace lidar_stereo_fusion {
namespace {

// ---- The field lists ------------------------------------------------------------------------

template <class P, class V>
void visitProjection(P& p, V& v) {
  v("min_depth", p.min_depth);
  v("max_depth", p.max_depth);
}

template <class P, class V>
void visitBI(P& p, V& v) {
  v("max_gap_px", p.max_gap_px);
  v("max_jump_disp", p.max_jump_disp);
  v("max_disp_diff", p.max_disp_diff);
  v("max_color_diff", p.max_color_diff);
  v("search_lines", p.search_lines);
  v("max_interp_rows", p.max_interp_rows);
}

template <class P, class V>
void visitBF(P& p, V& v) {
  v("radius", p.radius);
  v("sigma_space", p.sigma_space);
  v("sigma_range", p.sigma_range);
  v("min_support", p.min_support);
}

template <class P, class V>
void visitConfidence(P& p, V& v) {
  v("edge_tolerance", p.edge_tolerance);
  v("edge_sigma", p.edge_sigma);
  v("max_surface_slope", p.max_surface_slope);
  v("removed_factor", p.removed_factor);
  v("near_rows", p.near_rows);
  v("decay_rows", p.decay_rows);
  v("hole_confidence", p.hole_confidence);
}

template <class P, class V>
void visitPatchMatch(P& p, V& v) {
  v("window_radius", p.window_radius);
  v("window_stride", p.window_stride);
  v("window_dyadic", p.window_dyadic);
  v("weight_delta", p.weight_delta);
  v("alpha", p.alpha);
  v("beta", p.beta);
  v("gamma", p.gamma);
  v("lambda_col", p.lambda_col);
  v("lambda_grad", p.lambda_grad);
  v("lambda_disp", p.lambda_disp);
  v("iterations", p.iterations);
  v("right_iterations", p.right_iterations);
  v("slanted", p.slanted);
  v("init_from_prior", p.init_from_prior);
  v("init_normal_from_prior", p.init_normal_from_prior);
  v("use_lidar_bounds", p.use_lidar_bounds);
  v("bound_margin", p.bound_margin);
  v("min_refine_range", p.min_refine_range);
  v("min_disparity", p.min_disparity);
  v("max_disparity", p.max_disparity);
  v("view_propagation", p.view_propagation);
  v("lr_check", p.lr_check);
  v("lr_max_diff", p.lr_max_diff);
  v("median_radius", p.median_radius);
  v("confidence_weighting", p.confidence_weighting);
  v("lock_confidence", p.lock_confidence);
  v("fill_confidence", p.fill_confidence);
  v("coarse_scale", p.coarse_scale);
  v("coarse_levels", p.coarse_levels);
  v("full_size_unbounded", p.full_size_unbounded);
  v("fine_iterations", p.fine_iterations);
  v("fine_refine_range", p.fine_refine_range);
  v("fine_right_view", p.fine_right_view);
  v("fine_subpixel", p.fine_subpixel);
  v("num_threads", p.num_threads);
  v("seed", p.seed);
}

/// Calls `section(name, visit_fields)` for every section of FusionParams.
template <class F, class S>
void visitSections(F& params, S& section) {
  section("projection", [&](auto& v) { visitProjection(params.projection, v); });
  section("bi", [&](auto& v) { visitBI(params.bi, v); });
  section("bf", [&](auto& v) { visitBF(params.bf, v); });
  section("confidence", [&](auto& v) { visitConfidence(params.confidence, v); });
  section("patchmatch", [&](auto& v) { visitPatchMatch(params.patchmatch, v); });
}

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

/// Reads scalar values of one section, with errors naming file and key.
class FieldReader {
 public:
  FieldReader(const cv::FileNode& section, std::string where)
      : section_(section), where_(std::move(where)) {}

  template <class T>
  void operator()(const std::string& key, T& value) {
    known_.insert(key);
    const cv::FileNode node = section_[key];
    if (!node.empty()) read(node, key, value);
  }

  /// Throws when the section has a key that no field claimed.
  void rejectUnknownKeys() const {
    for (const cv::FileNode& node : section_) {
      if (known_.count(node.name()) == 0) {
        std::string valid;
        for (const std::string& k : known_) valid += (valid.empty() ? "" : ", ") + k;
        throw std::runtime_error(where_ + ": unknown key '" + node.name() + "' (valid: " + valid +
                                 ")");
      }
    }
  }

 private:
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw std::runtime_error(where_ + ": key '" + key + "' " + what);
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

  cv::FileNode section_;
  std::string where_;
  std::set<std::string> known_;
};

/// OpenCV's YAML reader needs a "%YAML" directive; rosparam files have none.
std::string withYamlDirective(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && text.compare(first, 5, "%YAML") == 0) return text;
  if (first != std::string::npos && text.compare(first, 3, "---") == 0) return "%YAML:1.0\n" + text;
  return "%YAML:1.0\n---\n" + text;
}

cv::FileStorage openYaml(const std::string& path) {
  const std::string raw = readTextFile(path, "params YAML");
  requireTextFile(raw, path, "params YAML");
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

void readMethod(const cv::FileNode& node, const std::string& path, Method& method) {
  if (!node.isString())
    throw std::runtime_error("params YAML " + path + ": key 'method' must be a name");
  try {
    method = parseMethod(scalarString(node));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("params YAML " + path + ": key 'method': " + e.what());
  }
}

// ---- Writing --------------------------------------------------------------------------------

std::string formatDouble(double v) {
  char buf[64];
  // Shortest text that reads back to the same double ("200", "0.1").
  const auto result = std::to_chars(buf, buf + sizeof(buf), v);
  std::string s(buf, result.ptr);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";  // keep it a real number
  return s;
}

class FieldWriter {
 public:
  explicit FieldWriter(std::ostream& out) : out_(out) {}
  void operator()(const std::string& key, double v) { line(key, formatDouble(v)); }
  void operator()(const std::string& key, int v) { line(key, std::to_string(v)); }
  void operator()(const std::string& key, bool v) { line(key, v ? "true" : "false"); }
  void operator()(const std::string& key, uint64_t v) {
    const bool fits = v <= static_cast<uint64_t>(std::numeric_limits<int>::max());
    line(key, fits ? std::to_string(v) : "\"" + std::to_string(v) + "\"");
  }

 private:
  void line(const std::string& key, const std::string& value) {
    out_ << "  " << key << ": " << value << "\n";
  }
  std::ostream& out_;
};

}  // namespace

void loadParamsYaml(const std::string& path, FusionParams& params) {
  cv::FileStorage fs = openYaml(path);
  const cv::FileNode root = fs.root();
  FusionParams loaded = params;
  std::set<std::string> sections = {"method"};
  if (!root.empty() && !root.isNone()) {
    if (!root.isMap()) throw std::runtime_error("params YAML " + path + ": top level is not a map");
    auto section = [&](const std::string& name, auto visit_fields) {
      sections.insert(name);
      const cv::FileNode node = root[name];
      if (node.empty()) return;
      if (!node.isMap()) {
        throw std::runtime_error("params YAML " + path + ": '" + name + "' must be a map");
      }
      FieldReader reader(node, "params YAML " + path + " section '" + name + "'");
      visit_fields(reader);
      reader.rejectUnknownKeys();
    };
    visitSections(loaded, section);
    if (!root["method"].empty()) readMethod(root["method"], path, loaded.method);
    for (const cv::FileNode& node : root) {
      if (sections.count(node.name()) == 0) {
        throw std::runtime_error("params YAML " + path + ": unknown key '" + node.name() +
                                 "' (valid: method, projection, bi, bf, patchmatch)");
      }
    }
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
  out << "# lidar_stereo_fusion parameters (every field; see include/lidar_stereo_fusion/core)\n";
  out << "method: " << methodName(params.method) << "\n";
  FieldWriter writer(out);
  auto section = [&](const std::string& name, auto visit_fields) {
    out << name << ":\n";
    visit_fields(writer);
  };
  visitSections(params, section);
  std::ofstream file(path);
  if (!file) throw std::runtime_error("params YAML: cannot create " + path);
  file << out.str();
  if (!file) throw std::runtime_error("params YAML: cannot write " + path);
}

}  // namespace lidar_stereo_fusion
