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

constexpr int kMaxThreads = 256;  ///< as PatchMatchParams::validate()

/// The deprecated spellings of a parameter: ~group/field (the grouped YAML loaded by rosparam) and
/// group_field (the former dynamic_reconfigure name).
std::vector<std::string> deprecatedNames(const ParamName& n) {
  if (*n.group == '\0') return {};
  return {std::string(n.group) + "/" + n.name, std::string(n.group) + "_" + n.name};
}

// Reading from the parameter server -----------------------------------------------------------
struct Reader {
  const ros::NodeHandle& nh;
  std::vector<std::string>& errors;

  /// The value under the name, or else under a deprecated name (said, and deleted so that the
  /// parameter server holds one spelling).
  bool fetch(const ParamName& n, XmlRpc::XmlRpcValue& value) const {
    bool found = nh.hasParam(n.name) && nh.getParam(n.name, value);
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
  void wrongType(const ParamName& n, const char* expected, XmlRpc::XmlRpcValue& value) {
    std::ostringstream s;
    s << "parameter " << nh.resolveName(n.name) << ": expected " << expected << ", got '"
      << value.toXml() << "'; keeping the previous value";
    errors.push_back(s.str());
  }
  void operator()(const ParamName& n, double& out) {
    XmlRpc::XmlRpcValue v;
    if (!fetch(n, v)) return;
    if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
      out = static_cast<double>(v);
    } else if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
      out = static_cast<int>(v);
    } else {
      wrongType(n, "a number", v);
    }
  }
  void operator()(const ParamName& n, int& out) {
    XmlRpc::XmlRpcValue v;
    if (!fetch(n, v)) return;
    if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
      out = static_cast<int>(v);
    } else {
      wrongType(n, "an integer", v);
    }
  }
  void operator()(const ParamName& n, bool& out) {
    XmlRpc::XmlRpcValue v;
    if (!fetch(n, v)) return;
    if (v.getType() == XmlRpc::XmlRpcValue::TypeBoolean) {
      out = static_cast<bool>(v);
    } else {
      wrongType(n, "true or false", v);
    }
  }
  void operator()(const ParamName& n, Method& out) {
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
  void operator()(const ParamName& n, uint64_t& out) {
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
  void operator()(const ParamName& n, const double& v) { nh.setParam(n.name, v); }
  void operator()(const ParamName& n, const int& v) { nh.setParam(n.name, v); }
  void operator()(const ParamName& n, const bool& v) { nh.setParam(n.name, v); }
  void operator()(const ParamName& n, const Method& v) { nh.setParam(n.name, methodName(v)); }
  void operator()(const ParamName& n, const uint64_t& v) {
    nh.setParam(n.name, static_cast<int>(v));
  }
};

// dynamic_reconfigure messages ----------------------------------------------------------------
template <class Entry>
Entry* findEntry(std::vector<Entry>& entries, const std::string& name) {
  for (auto& e : entries) {
    if (e.name == name) return &e;
  }
  throw std::logic_error("cfg/Fusion.cfg has no parameter '" + name +
                         "' (cfg and ros_params.cpp are out of sync)");
}

/// Writes FusionParams into a dynamic_reconfigure::Config message.
struct ToMessage {
  dynamic_reconfigure::Config& msg;
  void operator()(const ParamName& n, const double& v) {
    findEntry(msg.doubles, n.name)->value = v;
  }
  void operator()(const ParamName& n, const int& v) { findEntry(msg.ints, n.name)->value = v; }
  void operator()(const ParamName& n, const bool& v) { findEntry(msg.bools, n.name)->value = v; }
  void operator()(const ParamName& n, const Method& v) {
    findEntry(msg.strs, n.name)->value = methodName(v);
  }
  void operator()(const ParamName& n, const uint64_t& v) {
    const uint64_t max = static_cast<uint64_t>(std::numeric_limits<int>::max());
    findEntry(msg.ints, n.name)->value = static_cast<int>(v > max ? max : v);
  }
};

/// Reads FusionParams from a dynamic_reconfigure::Config message; throws std::invalid_argument
/// naming the parameter for values no field can hold.
struct FromMessage {
  dynamic_reconfigure::Config& msg;
  void operator()(const ParamName& n, double& v) {
    v = findEntry(msg.doubles, n.name)->value;
    if (!std::isfinite(v)) throw std::invalid_argument(std::string(n.name) + " must be finite");
  }
  void operator()(const ParamName& n, int& v) { v = findEntry(msg.ints, n.name)->value; }
  void operator()(const ParamName& n, bool& v) { v = findEntry(msg.bools, n.name)->value; }
  void operator()(const ParamName& n, Method& v) {
    const std::string& name = findEntry(msg.strs, n.name)->value;
    try {
      v = parseMethod(name);
    } catch (const std::exception& e) {
      throw std::invalid_argument(std::string(n.name) + ": " + e.what());
    }
  }
  void operator()(const ParamName& n, uint64_t& v) {
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
  void operator()(const ParamName& n, const T& v) {
    std::ostringstream s;
    s << std::boolalpha << v;
    out.emplace_back(n.name, s.str());
  }
  void operator()(const ParamName& n, const double& v) {
    out.emplace_back(n.name, formatParamDouble(v));
  }
  void operator()(const ParamName& n, const Method& v) { out.emplace_back(n.name, methodName(v)); }
};

}  // namespace

std::vector<ParamInfo> listParams() { return paramTable(); }

FusionParams readParams(const ros::NodeHandle& pnh, const FusionParams& base,
                        std::vector<std::string>* errors) {
  std::vector<std::string> local;
  std::vector<std::string>& errs = errors ? *errors : local;
  FusionParams p = base;
  visitParamTable(p, Reader{pnh, errs});
  // rosparam bypasses validate() until the whole set is checked; a thread count beyond this
  // crashes libgomp, so it is refused on its own.
  if (p.patchmatch.num_threads < 0 || p.patchmatch.num_threads > kMaxThreads) {
    errs.push_back("parameter " + pnh.resolveName("num_threads") + " = " +
                   std::to_string(p.patchmatch.num_threads) + " is out of range [0, " +
                   std::to_string(kMaxThreads) + "] (0 = all cores); keeping " +
                   std::to_string(base.patchmatch.num_threads));
    p.patchmatch.num_threads = base.patchmatch.num_threads;
  }

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

void writeParams(const ros::NodeHandle& pnh, const FusionParams& params) {
  visitParamTable(params, Writer{pnh});
}

FusionConfig toConfig(const FusionParams& params) {
  FusionConfig config = FusionConfig::__getDefault__();
  dynamic_reconfigure::Config msg;
  config.__toMessage__(msg);
  visitParamTable(params, ToMessage{msg});
  config.__fromMessage__(msg);
  return config;
}

FusionParams fromConfig(const FusionConfig& config) {
  dynamic_reconfigure::Config msg;
  config.__toMessage__(msg);
  FusionParams p;
  visitParamTable(p, FromMessage{msg});
  return p;
}

std::string describeChanges(const FusionParams& from, const FusionParams& to) {
  Stringifier sa, sb;
  visitParamTable(from, sa);
  visitParamTable(to, sb);
  std::string out;
  for (size_t i = 0; i < sa.out.size(); ++i) {
    if (sa.out[i].second == sb.out[i].second) continue;
    if (!out.empty()) out += ", ";
    out += sa.out[i].first + ": " + sa.out[i].second + " -> " + sb.out[i].second;
  }
  return out;
}

std::string describeRequest(const FusionParams& current, const FusionConfig& requested) {
  dynamic_reconfigure::Config now, asked;
  toConfig(current).__toMessage__(now);
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
