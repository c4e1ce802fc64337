#include "lidar_stereo_fusion/ros/ros_params.h"

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

constexpr int kMaxThreads = 256;  ///< as cfg/Fusion.cfg and PatchMatchParams::validate()

/// Calls v(group, field, value&) for every field of FusionParams, in declaration order. The value
/// types are double, int, bool, Method and uint64_t (the seed). This table is the only place that
/// lists the fields; the names are those of io/params_yaml.h.
template <class Visitor>
void visitParams(FusionParams& p, Visitor&& v) {
  v("", "method", p.method);
  v("projection", "min_depth", p.projection.min_depth);
  v("projection", "max_depth", p.projection.max_depth);
  v("bi", "max_gap_px", p.bi.max_gap_px);
  v("bi", "max_jump_disp", p.bi.max_jump_disp);
  v("bi", "max_disp_diff", p.bi.max_disp_diff);
  v("bi", "max_color_diff", p.bi.max_color_diff);
  v("bi", "search_lines", p.bi.search_lines);
  v("bi", "max_interp_rows", p.bi.max_interp_rows);
  v("bf", "radius", p.bf.radius);
  v("bf", "sigma_space", p.bf.sigma_space);
  v("bf", "sigma_range", p.bf.sigma_range);
  v("bf", "min_support", p.bf.min_support);
  v("confidence", "edge_tolerance", p.confidence.edge_tolerance);
  v("confidence", "edge_sigma", p.confidence.edge_sigma);
  v("confidence", "max_surface_slope", p.confidence.max_surface_slope);
  v("confidence", "removed_factor", p.confidence.removed_factor);
  v("confidence", "near_rows", p.confidence.near_rows);
  v("confidence", "decay_rows", p.confidence.decay_rows);
  v("confidence", "hole_confidence", p.confidence.hole_confidence);
  PatchMatchParams& m = p.patchmatch;
  v("patchmatch", "window_radius", m.window_radius);
  v("patchmatch", "window_stride", m.window_stride);
  v("patchmatch", "window_dyadic", m.window_dyadic);
  v("patchmatch", "weight_delta", m.weight_delta);
  v("patchmatch", "alpha", m.alpha);
  v("patchmatch", "beta", m.beta);
  v("patchmatch", "gamma", m.gamma);
  v("patchmatch", "lambda_col", m.lambda_col);
  v("patchmatch", "lambda_grad", m.lambda_grad);
  v("patchmatch", "lambda_disp", m.lambda_disp);
  v("patchmatch", "iterations", m.iterations);
  v("patchmatch", "right_iterations", m.right_iterations);
  v("patchmatch", "slanted", m.slanted);
  v("patchmatch", "init_from_prior", m.init_from_prior);
  v("patchmatch", "init_normal_from_prior", m.init_normal_from_prior);
  v("patchmatch", "use_lidar_bounds", m.use_lidar_bounds);
  v("patchmatch", "bound_margin", m.bound_margin);
  v("patchmatch", "min_refine_range", m.min_refine_range);
  v("patchmatch", "min_disparity", m.min_disparity);
  v("patchmatch", "max_disparity", m.max_disparity);
  v("patchmatch", "view_propagation", m.view_propagation);
  v("patchmatch", "lr_check", m.lr_check);
  v("patchmatch", "lr_max_diff", m.lr_max_diff);
  v("patchmatch", "median_radius", m.median_radius);
  v("patchmatch", "confidence_weighting", m.confidence_weighting);
  v("patchmatch", "lock_confidence", m.lock_confidence);
  v("patchmatch", "fill_confidence", m.fill_confidence);
  v("patchmatch", "coarse_scale", m.coarse_scale);
  v("patchmatch", "coarse_levels", m.coarse_levels);
  v("patchmatch", "full_size_unbounded", m.full_size_unbounded);
  v("patchmatch", "fine_iterations", m.fine_iterations);
  v("patchmatch", "fine_refine_range", m.fine_refine_range);
  v("patchmatch", "fine_right_view", m.fine_right_view);
  v("patchmatch", "fine_subpixel", m.fine_subpixel);
  v("patchmatch", "num_threads", m.num_threads);
  v("patchmatch", "seed", m.seed);
}

const std::set<std::string>& groups() {
  static const std::set<std::string> kGroups = {"projection", "bi", "bf", "confidence", "patchmatch"};
  return kGroups;
}

std::string rosName(const std::string& group, const std::string& field) {
  return group.empty() ? field : group + "/" + field;
}
std::string reconfigureName(const std::string& group, const std::string& field) {
  return group.empty() ? field : group + "_" + field;
}

// Lister --------------------------------------------------------------------------------------
struct Lister {
  std::vector<ParamInfo>* out;
  void add(const std::string& g, const std::string& f, const char* type) {
    out->push_back({rosName(g, f), reconfigureName(g, f), type});
  }
  void operator()(const std::string& g, const std::string& f, double&) { add(g, f, "double"); }
  void operator()(const std::string& g, const std::string& f, int&) { add(g, f, "int"); }
  void operator()(const std::string& g, const std::string& f, bool&) { add(g, f, "bool"); }
  void operator()(const std::string& g, const std::string& f, Method&) { add(g, f, "string"); }
  void operator()(const std::string& g, const std::string& f, uint64_t&) { add(g, f, "int"); }
};

// Reading from the parameter server -----------------------------------------------------------
struct Reader {
  const ros::NodeHandle& nh;
  std::vector<std::string>& errors;

  bool fetch(const std::string& name, XmlRpc::XmlRpcValue& value) const {
    return nh.hasParam(name) && nh.getParam(name, value);
  }
  void wrongType(const std::string& name, const char* expected, XmlRpc::XmlRpcValue& value) {
    std::ostringstream s;
    s << "parameter " << nh.resolveName(name) << ": expected " << expected << ", got '"
      << value.toXml() << "'; keeping the previous value";
    errors.push_back(s.str());
  }
  void operator()(const std::string& g, const std::string& f, double& out) {
    XmlRpc::XmlRpcValue v;
    if (!fetch(rosName(g, f), v)) return;
    if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
      out = static_cast<double>(v);
    } else if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
      out = static_cast<int>(v);
    } else {
      wrongType(rosName(g, f), "a number", v);
    }
  }
  void operator()(const std::string& g, const std::string& f, int& out) {
    XmlRpc::XmlRpcValue v;
    if (!fetch(rosName(g, f), v)) return;
    if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
      out = static_cast<int>(v);
    } else {
      wrongType(rosName(g, f), "an integer", v);
    }
  }
  void operator()(const std::string& g, const std::string& f, bool& out) {
    XmlRpc::XmlRpcValue v;
    if (!fetch(rosName(g, f), v)) return;
    if (v.getType() == XmlRpc::XmlRpcValue::TypeBoolean) {
      out = static_cast<bool>(v);
    } else {
      wrongType(rosName(g, f), "true or false", v);
    }
  }
  void operator()(const std::string& g, const std::string& f, Method& out) {
    XmlRpc::XmlRpcValue v;
    if (!fetch(rosName(g, f), v)) return;
    if (v.getType() != XmlRpc::XmlRpcValue::TypeString) {
      wrongType(rosName(g, f), "a method name", v);
      return;
    }
    try {
      out = parseMethod(static_cast<std::string>(v));
    } catch (const std::exception& e) {
      errors.push_back("parameter " + nh.resolveName(rosName(g, f)) + ": " + e.what() +
                       "; keeping the previous value");
    }
  }
  void operator()(const std::string& g, const std::string& f, uint64_t& out) {
    XmlRpc::XmlRpcValue v;
    if (!fetch(rosName(g, f), v)) return;
    if (v.getType() == XmlRpc::XmlRpcValue::TypeInt && static_cast<int>(v) >= 0) {
      out = static_cast<uint64_t>(static_cast<int>(v));
    } else {
      wrongType(rosName(g, f), "a non-negative integer", v);
    }
  }
};

// Writing to the parameter server -------------------------------------------------------------
struct Writer {
  const ros::NodeHandle& nh;
  void operator()(const std::string& g, const std::string& f, double& v) {
    nh.setParam(rosName(g, f), v);
  }
  void operator()(const std::string& g, const std::string& f, int& v) {
    nh.setParam(rosName(g, f), v);
  }
  void operator()(const std::string& g, const std::string& f, bool& v) {
    nh.setParam(rosName(g, f), v);
  }
  void operator()(const std::string& g, const std::string& f, Method& v) {
    nh.setParam(rosName(g, f), methodName(v));
  }
  void operator()(const std::string& g, const std::string& f, uint64_t& v) {
    nh.setParam(rosName(g, f), static_cast<int>(v));
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
  void operator()(const std::string& g, const std::string& f, double& v) {
    findEntry(msg.doubles, reconfigureName(g, f))->value = v;
  }
  void operator()(const std::string& g, const std::string& f, int& v) {
    findEntry(msg.ints, reconfigureName(g, f))->value = v;
  }
  void operator()(const std::string& g, const std::string& f, bool& v) {
    findEntry(msg.bools, reconfigureName(g, f))->value = v;
  }
  void operator()(const std::string& g, const std::string& f, Method& v) {
    findEntry(msg.strs, reconfigureName(g, f))->value = methodName(v);
  }
  void operator()(const std::string& g, const std::string& f, uint64_t& v) {
    const uint64_t max = static_cast<uint64_t>(std::numeric_limits<int>::max());
    findEntry(msg.ints, reconfigureName(g, f))->value = static_cast<int>(v > max ? max : v);
  }
};

/// Reads FusionParams from a dynamic_reconfigure::Config message.
struct FromMessage {
  dynamic_reconfigure::Config& msg;
  void operator()(const std::string& g, const std::string& f, double& v) {
    v = findEntry(msg.doubles, reconfigureName(g, f))->value;
  }
  void operator()(const std::string& g, const std::string& f, int& v) {
    v = findEntry(msg.ints, reconfigureName(g, f))->value;
  }
  void operator()(const std::string& g, const std::string& f, bool& v) {
    v = findEntry(msg.bools, reconfigureName(g, f))->value;
  }
  void operator()(const std::string& g, const std::string& f, Method& v) {
    const std::string& name = findEntry(msg.strs, reconfigureName(g, f))->value;
    try {
      v = parseMethod(name);
    } catch (const std::exception& e) {
      throw std::invalid_argument(reconfigureName(g, f) + ": " + e.what());
    }
  }
  void operator()(const std::string& g, const std::string& f, uint64_t& v) {
    const int value = findEntry(msg.ints, reconfigureName(g, f))->value;
    if (value < 0) {
      throw std::invalid_argument(reconfigureName(g, f) + " must be >= 0, got " +
                                  std::to_string(value));
    }
    v = static_cast<uint64_t>(value);
  }
};

/// Collects every field as text, for describeChanges().
struct Stringifier {
  std::vector<std::pair<std::string, std::string>> out;
  template <class T>
  void operator()(const std::string& g, const std::string& f, T& v) {
    std::ostringstream s;
    s << std::boolalpha << v;
    out.emplace_back(rosName(g, f), s.str());
  }
  void operator()(const std::string& g, const std::string& f, Method& v) {
    out.emplace_back(rosName(g, f), methodName(v));
  }
};

}  // namespace

std::vector<ParamInfo> listParams() {
  std::vector<ParamInfo> out;
  FusionParams p;
  visitParams(p, Lister{&out});
  return out;
}

FusionParams readParams(const ros::NodeHandle& pnh, const FusionParams& base,
                        std::vector<std::string>* errors) {
  std::vector<std::string> local;
  std::vector<std::string>& errs = errors ? *errors : local;
  FusionParams p = base;
  visitParams(p, Reader{pnh, errs});
  // rosparam and YAML bypass dynamic_reconfigure's range; a thread count beyond it crashes libgomp.
  if (p.patchmatch.num_threads < 0 || p.patchmatch.num_threads > kMaxThreads) {
    errs.push_back("parameter " + pnh.resolveName("patchmatch/num_threads") + " = " +
                   std::to_string(p.patchmatch.num_threads) + " is out of range [0, " +
                   std::to_string(kMaxThreads) + "] (0 = all cores); keeping " +
                   std::to_string(base.patchmatch.num_threads));
    p.patchmatch.num_threads = base.patchmatch.num_threads;
  }

  // Unknown keys under the groups are typos: name them (they would otherwise be ignored).
  std::set<std::string> known;
  for (const auto& info : listParams()) known.insert(pnh.resolveName(info.ros_name));
  std::vector<std::string> names;
  if (ros::param::getParamNames(names)) {
    for (const auto& group : groups()) {
      const std::string prefix = pnh.resolveName(group) + "/";
      for (const auto& name : names) {
        if (name.compare(0, prefix.size(), prefix) == 0 && !known.count(name)) {
          errs.push_back("unknown parameter " + name + " (typo?) is ignored");
        }
      }
    }
  }
  return p;
}

void writeParams(const ros::NodeHandle& pnh, const FusionParams& params) {
  FusionParams p = params;
  visitParams(p, Writer{pnh});
}

FusionConfig toConfig(const FusionParams& params) {
  FusionConfig config = FusionConfig::__getDefault__();
  dynamic_reconfigure::Config msg;
  config.__toMessage__(msg);
  FusionParams p = params;
  visitParams(p, ToMessage{msg});
  config.__fromMessage__(msg);
  return config;
}

FusionParams fromConfig(const FusionConfig& config) {
  dynamic_reconfigure::Config msg;
  config.__toMessage__(msg);
  FusionParams p;
  visitParams(p, FromMessage{msg});
  return p;
}

std::string describeChanges(const FusionParams& from, const FusionParams& to) {
  FusionParams a = from, b = to;
  Stringifier sa, sb;
  visitParams(a, sa);
  visitParams(b, sb);
  std::string out;
  for (size_t i = 0; i < sa.out.size(); ++i) {
    if (sa.out[i].second == sb.out[i].second) continue;
    if (!out.empty()) out += ", ";
    out += sa.out[i].first + ": " + sa.out[i].second + " -> " + sb.out[i].second;
  }
  return out;
}

}  // namespace ros_params
}  // namespace lidar_stereo_fusion
