#include "lidar_stereo_fusion/io/param_table.h"

#include <charconv>

namespace lidar_stereo_fusion {

namespace {

struct Lister {
  std::vector<ParamInfo>& out;
  void add(const ParamName& n, const char* type, std::string value) {
    out.push_back({n.name, n.group, type, std::move(value)});
  }
  void operator()(const ParamName& n, const Method& v) { add(n, "string", methodName(v)); }
  void operator()(const ParamName& n, const double& v) { add(n, "double", formatParamDouble(v)); }
  void operator()(const ParamName& n, const int& v) { add(n, "int", std::to_string(v)); }
  void operator()(const ParamName& n, const bool& v) { add(n, "bool", v ? "true" : "false"); }
  void operator()(const ParamName& n, const uint64_t& v) { add(n, "int", std::to_string(v)); }
};

}  // namespace

std::vector<ParamInfo> paramTable() {
  std::vector<ParamInfo> out;
  const FusionParams defaults;
  visitParamTable(defaults, Lister{out});
  return out;
}

std::vector<std::string> paramGroups() {
  std::vector<std::string> groups;
  for (const ParamInfo& p : paramTable()) {
    if (!p.group.empty() && (groups.empty() || groups.back() != p.group)) groups.push_back(p.group);
  }
  return groups;
}

std::string formatParamDouble(double v) {
  char buf[64];
  const auto result = std::to_chars(buf, buf + sizeof(buf), v);
  std::string s(buf, result.ptr);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";  // keep it a real number
  return s;
}

}  // namespace lidar_stereo_fusion
