// The parameter table (core/param_table.h) as data: one ParamInfo per row, with the default of
// FusionParams{} as text, for the YAML reader, the docs and the tests.
#pragma once

#include <string>
#include <vector>

#include "lidar_stereo_fusion/core/param_table.h"

namespace lidar_stereo_fusion {

/// One row of a parameter table, with its type and default as text.
struct ParamInfo {
  std::string name, group;
  std::string type;           ///< "string", "double", "int" or "bool"
  std::string default_value;  ///< as YAML writes it (doubles shortest round-trip, "200.0")
  std::string range;          ///< ParamRange::text() for numbers ("in [1, 50]"), else ""
  std::string unit, doc, choices;
  bool live = true;  ///< dynamic_reconfigure may change it
};

/// Lists the rows `visit(defaults, visitor)` walks (any table: FusionParams, NodeParams).
struct ParamLister {
  std::vector<ParamInfo>& out;
  void add(const ParamSpec& s, const char* type, std::string value) const;
  void operator()(const ParamSpec& s, const Method& v) const;
  void operator()(const ParamSpec& s, const double& v) const;
  void operator()(const ParamSpec& s, const int& v) const;
  void operator()(const ParamSpec& s, const bool& v) const;
  void operator()(const ParamSpec& s, const uint64_t& v) const;
  void operator()(const ParamSpec& s, const std::string& v) const;
};

/// Every parameter of FusionParams, in table order.
std::vector<ParamInfo> paramTable();

/// The groups, in table order ("projection", "bi", "bf", "confidence", "patchmatch").
std::vector<std::string> paramGroups();

}  // namespace lidar_stereo_fusion
