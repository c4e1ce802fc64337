#include "lidar_stereo_fusion/io/param_table.h"

namespace lidar_stereo_fusion {

void ParamLister::add(const ParamSpec& s, const char* type, std::string value) const {
  const bool number = std::string(type) == "double" || std::string(type) == "int";
  out.push_back({s.name, s.group, type, std::move(value), number ? s.range.text() : "", s.unit,
                 s.doc, s.choices, s.live == Live::kYes});
}
void ParamLister::operator()(const ParamSpec& s, const Method& v) const {
  add(s, "string", methodName(v));
}
void ParamLister::operator()(const ParamSpec& s, const double& v) const {
  add(s, "double", formatParamDouble(v));
}
void ParamLister::operator()(const ParamSpec& s, const int& v) const {
  add(s, "int", std::to_string(v));
}
void ParamLister::operator()(const ParamSpec& s, const bool& v) const {
  add(s, "bool", v ? "true" : "false");
}
void ParamLister::operator()(const ParamSpec& s, const uint64_t& v) const {
  add(s, "int", std::to_string(v));
}
void ParamLister::operator()(const ParamSpec& s, const std::string& v) const {
  add(s, "string", v);
}

std::vector<ParamInfo> paramTable() {
  std::vector<ParamInfo> out;
  const FusionParams defaults;
  visitParamTable(defaults, ParamLister{out});
  return out;
}

std::vector<std::string> paramGroups() {
  std::vector<std::string> groups;
  for (const ParamInfo& p : paramTable()) {
    if (!p.group.empty() && (groups.empty() || groups.back() != p.group)) groups.push_back(p.group);
  }
  return groups;
}

}  // namespace lidar_stereo_fusion
