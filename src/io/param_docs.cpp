// Rendering the parameter tables as YAML, Markdown and cfg/Fusion.cfg (io/param_docs.h).
#include "lidar_stereo_fusion/io/param_docs.h"

#include <limits>
#include <sstream>
#include <stdexcept>

namespace lidar_stereo_fusion {

namespace {

/// "a | b | c" of "a|b|c".
std::string choiceList(const std::string& choices) {
  std::string out;
  for (const std::string& word : choiceWords(choices)) out += (out.empty() ? "" : " | ") + word;
  return out;
}

/// "[m] Points closer ...; allowed: > 0": what a YAML comment and the cfg description say.
std::string describe(const ParamInfo& p) {
  std::string text = p.unit.empty() ? p.doc : "[" + p.unit + "] " + p.doc;
  if (!p.range.empty() && p.range != "finite") text += "; allowed: " + p.range;
  if (!p.choices.empty()) text += "; allowed: " + choiceList(p.choices);
  return text;
}

std::string yamlValue(const ParamInfo& p) {
  if (p.type == "string" && p.default_value.empty()) return "\"\"";
  if (p.type == "int") {  // OpenCV's reader has no 64-bit integers: larger seeds are quoted
    const long double v = std::stold(p.default_value);
    if (v > std::numeric_limits<int>::max()) return "\"" + p.default_value + "\"";
  }
  return p.default_value;
}

std::string pythonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string pythonValue(const ParamInfo& p) {
  if (p.type == "bool") return p.default_value == "true" ? "True" : "False";
  if (p.type == "string") return pythonString(p.default_value);
  return p.default_value;
}

std::string markdownCell(std::string s) {
  std::string out;
  for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

}  // namespace

std::string renderParamsYaml(const std::vector<ParamInfo>& rows, const std::string& header) {
  std::ostringstream out;
  std::istringstream lines(header);
  for (std::string line; std::getline(lines, line);)
    out << (line.empty() ? "#" : "# " + line) << "\n";
  std::string group = "\x01", section;
  for (const ParamInfo& p : rows) {
    const auto slash = p.name.find('/');
    const std::string sec = slash == std::string::npos ? "" : p.name.substr(0, slash);
    const std::string key = slash == std::string::npos ? p.name : p.name.substr(slash + 1);
    if (p.group != group) {
      out << "\n";
      if (!p.group.empty()) out << "# ---- " << p.group << "\n";
      group = p.group;
    }
    if (sec != section && !sec.empty()) out << sec << ":\n";
    section = sec;
    const std::string indent = sec.empty() ? "" : "  ";
    out << indent << "# " << describe(p) << "\n" << indent << key << ": " << yamlValue(p) << "\n";
  }
  return out.str();
}

std::string renderParamsMarkdown(const std::vector<ParamInfo>& rows, bool live_column) {
  std::ostringstream out;
  out << "| group | parameter | default | allowed | meaning |" << (live_column ? " live |" : "")
      << "\n|---|---|---|---|---|" << (live_column ? "---|" : "") << "\n";
  for (const ParamInfo& p : rows) {
    std::string value = p.type == "string" && p.default_value.empty() ? "\"\"" : p.default_value;
    if (!p.unit.empty()) value += " " + p.unit;
    std::string allowed = p.type == "bool" ? "true, false" : p.range;
    if (!p.choices.empty()) allowed = choiceList(p.choices);
    if (p.type == "string" && p.choices.empty()) allowed = "a frame name";
    out << "| " << p.group << " | `" << p.name << "` | " << markdownCell(value) << " | "
        << markdownCell(allowed) << " | " << markdownCell(p.doc) << " |"
        << (live_column ? (p.live ? " yes |" : " no |") : "") << "\n";
  }
  return out.str();
}

std::string renderFusionCfg(const std::vector<ParamInfo>& rows) {
  std::ostringstream out;
  out << "#!/usr/bin/env python3\n"
         "# GENERATED from the parameter tables (include/lidar_stereo_fusion/core/param_table.h,\n"
         "# include/lidar_stereo_fusion/ros/node_params.h) by `rosrun lidar_stereo_fusion "
         "lsf_params\n"
         "# --write <source dir>`; do not edit (test_tools fails when it differs).\n"
         "# Live parameters of lidar_stereo_fusion/FusionNodelet:\n"
         "#   rosrun dynamic_reconfigure dynparam set /fusion/fusion window_radius 5\n"
         "# No slider ranges: the server would clamp silently. The node checks every request with\n"
         "# the table's ranges and validate(), refuses an invalid one as a whole with an error\n"
         "# naming the parameter, and answers with the values in force.\n"
         "PACKAGE = \"lidar_stereo_fusion\"\n\n"
         "from dynamic_reconfigure.parameter_generator_catkin import ParameterGenerator, bool_t, "
         "double_t, int_t, str_t\n\n"
         "gen = ParameterGenerator()\n";
  const auto typeName = [](const std::string& t) {
    return t == "double" ? "double_t" : t == "int" ? "int_t" : t == "bool" ? "bool_t" : "str_t";
  };
  std::string group = "\x01";
  for (const ParamInfo& p : rows) {
    if (!p.live) continue;
    if (p.group != group) {
      out << "\n";
      if (!p.group.empty()) out << p.group << " = gen.add_group(\"" << p.group << "\")\n";
      group = p.group;
    }
    const std::string owner = p.group.empty() ? "gen" : p.group;
    std::string edit;
    if (!p.choices.empty()) {
      out << p.name << "_enum = gen.enum([";
      for (const std::string& word : choiceWords(p.choices)) {
        out << "\n    gen.const(\"" << word << "\", str_t, \"" << word << "\", \"" << word
            << "\"),";
      }
      out << "\n], " << pythonString(p.doc) << ")\n";
      edit = ", edit_method=" + p.name + "_enum";
    }
    out << owner << ".add(\"" << p.name << "\", " << typeName(p.type) << ", 0, "
        << pythonString(describe(p)) << ", " << pythonValue(p) << edit << ")\n";
  }
  out << "\nexit(gen.generate(PACKAGE, \"lidar_stereo_fusion\", \"Fusion\"))\n";
  return out.str();
}

std::string replaceBetween(const std::string& text, const std::string& begin,
                           const std::string& end, const std::string& block) {
  const auto b = text.find(begin);
  const auto e = b == std::string::npos ? b : text.find(end, b + begin.size());
  if (b == std::string::npos || e == std::string::npos) {
    throw std::runtime_error("the markers '" + begin + "' and '" + end + "' are missing");
  }
  const auto after_begin = text.find('\n', b) + 1;
  return text.substr(0, after_begin) + block + text.substr(e);
}

}  // namespace lidar_stereo_fusion
