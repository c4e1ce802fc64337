#include "lidar_stereo_fusion/ros/ros_params.h"

#include "lidar_stereo_fusion/io/param_table.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include <dynamic_reconfigure/Config.h>
#include <ros/param.h>
#include <xmlrpcpp/XmlRpcValue.h>

namespace lidar_stereo_fusion {
namespace ros_params {

namespace {

/// The deprecated spellings of a parameter: ~group/field (the grouped YAML loaded by rosparam) and
/// group_field (the former dynamic_reconfigure name).
std::vector<std::string> deprecatedNames(const ParamSpec& n) {
  if (*n.group == '\0') return {};
  return {std::string(n.group) + "/" + n.name, std::string(n.group) + "_" + n.name};
}

// Reading from the parameter server -----------------------------------------------------------
struct Reader {
  const ros::NodeHandle& nh;
  std::vector<std::string>& errors;
  bool aliases = true;  ///< the algorithm's deprecated grouped names (the node's have none)

  /// The value under the name, or else under a deprecated name (said, and deleted so that the
  /// parameter server holds one spelling).
  bool fetch(const ParamSpec& n, XmlRpc::XmlRpcValue& value) const {
    bool found = nh.hasParam(n.name) && nh.getParam(n.name, value);
    if (!aliases) return found;
    for (const std::string& old : deprecatedNames(n)) {
      XmlRpc::XmlRpcValue old_value;
      if (!nh.hasParam(old) || !nh.getParam(old, old_value)) continue;
      if (found) {
        errors.push_back("parameter " + nh.resolveName(old) + " is a deprecated name of " +
                         nh.resolveName(n.name) + ", which is also set: ignored");
      } else {
        errors.push_back("parameter " + nh.resolveName(old) + " is a deprecated name: use " +
                         nh.resolveName(n.name) + " (read this time)");
        value = old_value;
        found = true;
      }
      nh.deleteParam(old);
    }
    return found;
  }
  void wrongType(const ParamSpec& n, const char* expected, XmlRpc::XmlRpcValue& value) {
    std::ostringstream s;
    s << "parameter " << nh.resolveName(n.name) << ": expected " << expected << ", got '"
      << value.toXml() << "'; keeping the previous value";
    errors.push_back(s.str());
  }
  /// Takes `candidate` unless the row's range or choices refuse it (then says so, naming it).
  template <class T>
  void take(const ParamSpec& n, const T& candidate, T& out) {
    std::string problem;
    if constexpr (std::is_same_v<T, std::string>) {
      problem = choiceProblem(n, candidate);
    } else {
      problem = rangeProblem(n, static_cast<double>(candidate));
    }
    if (problem.empty()) {
      out = candidate;
    } else {
      errors.push_back("parameter " + nh.resolveName(n.name) + ": " + problem +
                       "; keeping the previous value");
    }
  }
  void operator()(const ParamSpec& n, double& out) {
    XmlRpc::XmlRpcValue v;
    if (!fetch(n, v)) return;
    if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
      take(n, static_cast<double>(v), out);
    } else if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
      take(n, static_cast<double>(static_cast<int>(v)), out);
    } else {
      wrongType(n, "a number", v);
    }
  }
  void operator()(const ParamSpec& n, int& out) {
    XmlRpc::XmlRpcValue v;
    if (!fetch(n, v)) return;
    if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
      take(n, static_cast<int>(v), out);
    } else {
      wrongType(n, "an integer", v);
    }
  }
  void operator()(const ParamSpec& n, bool& out) {
    XmlRpc::XmlRpcValue v;
    if (!fetch(n, v)) return;
    if (v.getType() == XmlRpc::XmlRpcValue::TypeBoolean) {
      out = static_cast<bool>(v);
    } else {
      wrongType(n, "true or false", v);
    }
  }
  void operator()(const ParamSpec& n, std::string& out) {
    XmlRpc::XmlRpcValue v;
    if (!fetch(n, v)) return;
    if (v.getType() == XmlRpc::XmlRpcValue::TypeString) {
      take(n, static_cast<std::string>(v), out);
    } else {
      wrongType(n, "text", v);
    }
  }
  void operator()(const ParamSpec& n, Method& out) {
    XmlRpc::XmlRpcValue v;
    if (!fetch(n, v)) return;
    if (v.getType() != XmlRpc::XmlRpcValue::TypeString) {
      wrongType(n, "a method name", v);
      return;
    }
    try {
      out = parseMethod(static_cast<std::string>(v));
    } catch (const std::exception& e) {
      errors.push_back("parameter " + nh.resolveName(n.name) + ": " + e.what() +
                       "; keeping the previous value");
    }
  }
  void operator()(const ParamSpec& n, uint64_t& out) {
    XmlRpc::XmlRpcValue v;
    if (!fetch(n, v)) return;
    if (v.getType() == XmlRpc::XmlRpcValue::TypeInt && static_cast<int>(v) >= 0) {
      out = static_cast<uint64_t>(static_cast<int>(v));
    } else {
      wrongType(n, "a non-negative integer", v);
    }
  }
};

// Writing to the parameter server -------------------------------------------------------------
struct Writer {
  const ros::NodeHandle& nh;
  void operator()(const ParamSpec& n, const double& v) { nh.setParam(n.name, v); }
  void operator()(const ParamSpec& n, const int& v) { nh.setParam(n.name, v); }
  void operator()(const ParamSpec& n, const bool& v) { nh.setParam(n.name, v); }
  void operator()(const ParamSpec& n, const std::string& v) { nh.setParam(n.name, v); }
  void operator()(const ParamSpec& n, const Method& v) { nh.setParam(n.name, methodName(v)); }
  void operator()(const ParamSpec& n, const uint64_t& v) {
    nh.setParam(n.name, static_cast<int>(v));
  }
};

/// Visits the rows dynamic_reconfigure carries: every algorithm row, the node's live ones.
template <class P, class V>
void visitLive(P& p, V&& v) {
  visitParamTable(p.fusion, v);
  visitParams(p.node, [&v](const ParamSpec& spec, auto& field) {
    if (spec.live == Live::kYes) v(spec, field);
  });
}

// dynamic_reconfigure messages ----------------------------------------------------------------
template <class Entry>
Entry* findEntry(std::vector<Entry>& entries, const std::string& name) {
  for (auto& e : entries) {
    if (e.name == name) return &e;
  }
  throw std::logic_error("cfg/Fusion.cfg has no parameter '" + name +
                         "' (cfg and ros_params.cpp are out of sync)");
}

/// Writes the live rows into a dynamic_reconfigure::Config message.
struct ToMessage {
  dynamic_reconfigure::Config& msg;
  void operator()(const ParamSpec& n, const double& v) {
    findEntry(msg.doubles, n.name)->value = v;
  }
  void operator()(const ParamSpec& n, const int& v) { findEntry(msg.ints, n.name)->value = v; }
  void operator()(const ParamSpec& n, const bool& v) { findEntry(msg.bools, n.name)->value = v; }
  void operator()(const ParamSpec& n, const Method& v) {
    findEntry(msg.strs, n.name)->value = methodName(v);
  }
  void operator()(const ParamSpec& n, const std::string& v) {
    findEntry(msg.strs, n.name)->value = v;
  }
  void operator()(const ParamSpec& n, const uint64_t& v) {
    const uint64_t max = static_cast<uint64_t>(std::numeric_limits<int>::max());
    findEntry(msg.ints, n.name)->value = static_cast<int>(v > max ? max : v);
  }
};

/// Reads the live rows from a dynamic_reconfigure::Config message; throws std::invalid_argument
/// naming the parameter for values no field can hold.
struct FromMessage {
  dynamic_reconfigure::Config& msg;
  void operator()(const ParamSpec& n, double& v) {
    v = findEntry(msg.doubles, n.name)->value;
    if (!std::isfinite(v)) throw std::invalid_argument(std::string(n.name) + " must be finite");
  }
  void operator()(const ParamSpec& n, int& v) { v = findEntry(msg.ints, n.name)->value; }
  void operator()(const ParamSpec& n, bool& v) { v = findEntry(msg.bools, n.name)->value; }
  void operator()(const ParamSpec& n, std::string& v) { v = findEntry(msg.strs, n.name)->value; }
  void operator()(const ParamSpec& n, Method& v) {
    const std::string& name = findEntry(msg.strs, n.name)->value;
    try {
      v = parseMethod(name);
    } catch (const std::exception& e) {
      throw std::invalid_argument(std::string(n.name) + ": " + e.what());
    }
  }
  void operator()(const ParamSpec& n, uint64_t& v) {
    const int value = findEntry(msg.ints, n.name)->value;
    if (value < 0) {
      throw std::invalid_argument(std::string(n.name) + " must be >= 0, got " +
                                  std::to_string(value));
    }
    v = static_cast<uint64_t>(value);
  }
};

/// Every entry of a Config message as name -> text.
std::vector<std::pair<std::string, std::string>> messageEntries(
    const dynamic_reconfigure::Config& m) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& e : m.strs) out.emplace_back(e.name, e.value);
  for (const auto& e : m.doubles) out.emplace_back(e.name, formatParamDouble(e.value));
  for (const auto& e : m.ints) out.emplace_back(e.name, std::to_string(e.value));
  for (const auto& e : m.bools) out.emplace_back(e.name, e.value ? "true" : "false");
  return out;
}

/// Collects every field as text, for describeChanges().
struct Stringifier {
  std::vector<std::pair<std::string, std::string>> out;
  template <class T>
  void operator()(const ParamSpec& n, const T& v) {
    std::ostringstream s;
    s << std::boolalpha << v;
    out.emplace_back(n.name, s.str());
  }
  void operator()(const ParamSpec& n, const double& v) {
    out.emplace_back(n.name, formatParamDouble(v));
  }
  void operator()(const ParamSpec& n, const Method& v) { out.emplace_back(n.name, methodName(v)); }
};

/// "name: old -> new" for each entry that differs (the same table on both sides).
std::string differences(const Stringifier& a, const Stringifier& b) {
  std::string out;
  for (size_t i = 0; i < a.out.size(); ++i) {
    if (a.out[i].second == b.out[i].second) continue;
    if (!out.empty()) out += ", ";
    out += a.out[i].first + ": " + a.out[i].second + " -> " + b.out[i].second;
  }
  return out;
}

/// What dynamic_reconfigure carries: the algorithm's rows and the node's live ones.
struct LiveSet {
  FusionParams fusion;
  NodeParams node;
};

}  // namespace

std::vector<ParamInfo> listParams() { return paramTable(); }

std::vector<ParamInfo> listNodeParams() { return nodeParamTable(); }

FusionParams readParams(const ros::NodeHandle& pnh, const FusionParams& base,
                        std::vector<std::string>* errors) {
  std::vector<std::string> local;
  std::vector<std::string>& errs = errors ? *errors : local;
  FusionParams p = base;
  visitParamTable(p, Reader{pnh, errs});
  // Keys left under the old groups are typos (the known ones were read and deleted above).
  std::vector<std::string> names;
  if (ros::param::getParamNames(names)) {
    for (const auto& group : paramGroups()) {
      const std::string prefix = pnh.resolveName(group) + "/";
      for (const auto& name : names) {
        if (name.compare(0, prefix.size(), prefix) == 0) {
          errs.push_back("unknown parameter " + name + " (typo? parameters have no group: ~" +
                         name.substr(prefix.size()) + ") is ignored");
        }
      }
    }
  }
  return p;
}

NodeParams readNodeParams(const ros::NodeHandle& pnh, std::vector<std::string>* errors) {
  std::vector<std::string> local;
  std::vector<std::string>& errs = errors ? *errors : local;
  NodeParams p;
  visitParams(p, Reader{pnh, errs, /*aliases=*/false});
  try {
    p.validate();  // the checks between rows; each row's range was checked as it was read
  } catch (const std::exception& e) {
    errs.push_back(std::string(e.what()) + "; using the defaults of every node parameter");
    p = NodeParams();
  }
  return p;
}

void writeParams(const ros::NodeHandle& pnh, const FusionParams& params) {
  visitParamTable(params, Writer{pnh});
}

FusionConfig toConfig(const FusionParams& params, const NodeParams& node) {
  FusionConfig config = FusionConfig::__getDefault__();
  dynamic_reconfigure::Config msg;
  config.__toMessage__(msg);
  const LiveSet set{params, node};
  visitLive(set, ToMessage{msg});
  config.__fromMessage__(msg);
  return config;
}

FusionParams fromConfig(const FusionConfig& config, NodeParams* node) {
  dynamic_reconfigure::Config msg;
  config.__toMessage__(msg);
  LiveSet set{FusionParams(), node ? *node : NodeParams()};
  visitLive(set, FromMessage{msg});
  if (node) *node = set.node;
  return set.fusion;
}

std::string describeChanges(const FusionParams& from, const FusionParams& to) {
  Stringifier sa, sb;
  visitParamTable(from, sa);
  visitParamTable(to, sb);
  return differences(sa, sb);
}

std::string describeChanges(const NodeParams& from, const NodeParams& to) {
  Stringifier sa, sb;
  visitParams(from, sa);
  visitParams(to, sb);
  return differences(sa, sb);
}

std::string describeRequest(const FusionParams& current, const NodeParams& node,
                            const FusionConfig& requested) {
  dynamic_reconfigure::Config now, asked;
  toConfig(current, node).__toMessage__(now);
  requested.__toMessage__(asked);
  const auto a = messageEntries(now), b = messageEntries(asked);
  std::string out;
  for (const auto& [name, value] : b) {
    for (const auto& [old_name, old_value] : a) {
      if (old_name != name || old_value == value) continue;
      if (!out.empty()) out += ", ";
      out += name + " = " + value + " (in force: " + old_value + ")";
    }
  }
  return out.empty() ? "no change" : out;
}

}  // namespace ros_params
}  // namespace lidar_stereo_fusion
