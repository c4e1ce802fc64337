// What the one parameter table (core/param_table.h, ros/node_params.h) says about a parameter
// besides its field: name, group, allowed range, unit, one line of documentation, and whether it
// may change while the node runs. The type and the default are the field's own (the struct's
// default member initialiser is the default, written once).
//
// Every check of a single value against its range goes through rangeProblem(), so validate(), the
// YAML reader, rosparam and dynamic_reconfigure all say the same sentence ("window_radius must be
// in [1, 50] px, got 0"). Checks between parameters (alpha + beta + gamma = 1, max_depth >
// min_depth, ...) stay in the validate() of the struct that holds them.
#pragma once

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace lidar_stereo_fusion {

/// Allowed values of a numeric parameter: an interval, each end closed or open, possibly
/// unbounded. A double must also be finite.
struct ParamRange {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;  ///< lo itself excluded
  bool hi_open = false;  ///< hi itself excluded

  bool contains(double v) const {
    if (!std::isfinite(v)) return false;
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  /// "in [1, 50]", "> 0", ">= 0", "in (0, 10]", "finite".
  std::string text() const;
};

constexpr double kUnbounded = std::numeric_limits<double>::infinity();
constexpr ParamRange anyFinite() { return {-kUnbounded, kUnbounded, false, false}; }
constexpr ParamRange atLeast(double lo) { return {lo, kUnbounded, false, false}; }
constexpr ParamRange above(double lo) { return {lo, kUnbounded, true, false}; }
constexpr ParamRange within(double lo, double hi) { return {lo, hi, false, false}; }
constexpr ParamRange aboveUpTo(double lo, double hi) { return {lo, hi, true, false}; }

/// Whether a running node may change the parameter (dynamic_reconfigure).
enum class Live { kYes, kStartup };

/// One row of the parameter table.
struct ParamSpec {
  const char* name;          ///< the one name: YAML key, ROS parameter, dynamic_reconfigure name
  const char* group;         ///< section in YAML, dynamic_reconfigure and the docs ("" = none)
  ParamRange range;          ///< numbers only; bool and text parameters ignore it
  const char* unit;          ///< "px", "m", "s", "Hz", "rows", ... ("" = none)
  const char* doc;           ///< one line for users
  const char* choices = "";  ///< text parameters: the allowed words, "a|b|c" ("" = any text)
  Live live = Live::kYes;
};

/// "" when `value` is allowed, else "<name> must be <range> <unit>, got <value>".
std::string rangeProblem(const ParamSpec& spec, double value);

/// The allowed words of a text parameter: "a|b|c" -> {a, b, c} ({} when `choices` is empty).
std::vector<std::string> choiceWords(const std::string& choices);

/// "" when `value` is one of spec.choices (or choices is empty), else
/// "<name> must be one of a, b, c, got '<value>'".
std::string choiceProblem(const ParamSpec& spec, const std::string& value);

/// The value as the docs and YAML write it: doubles shortest round-trip with a '.' ("200.0").
std::string formatParamDouble(double v);

/// Table visitor for validate(): throws std::invalid_argument("<owner>: <problem>") at the first
/// field outside its row's range or choices.
struct RangeChecker {
  const char* owner;
  template <class T>
  void operator()(const ParamSpec& spec, const T& value) const {
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
      fail(rangeProblem(spec, static_cast<double>(value)));
    } else if constexpr (std::is_same_v<T, std::string>) {
      fail(choiceProblem(spec, value));
    }
  }
  void fail(const std::string& problem) const {
    if (!problem.empty()) throw std::invalid_argument(std::string(owner) + ": " + problem);
  }
};

}  // namespace lidar_stereo_fusion
