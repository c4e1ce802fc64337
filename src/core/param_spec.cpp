// The one wording of a parameter's range problem (core/param_spec.h).
#include "lidar_stereo_fusion/core/param_spec.h"

#include <charconv>

namespace lidar_stereo_fusion {

namespace {

/// Integers without a fraction ("50"), other numbers as formatParamDouble.
std::string number(double v) {
  if (std::isfinite(v) && v == std::floor(v) && std::abs(v) < 1e15) {
    return std::to_string(static_cast<long long>(v));
  }
  return formatParamDouble(v);
}

}  // namespace

std::string ParamRange::text() const {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi) {
    return std::string("in ") + (lo_open ? "(" : "[") + number(lo) + ", " + number(hi) +
           (hi_open ? ")" : "]");
  }
  if (has_lo) return (lo_open ? "> " : ">= ") + number(lo);
  if (has_hi) return (hi_open ? "< " : "<= ") + number(hi);
  return "finite";
}

std::string rangeProblem(const ParamSpec& spec, double value) {
  if (spec.range.contains(value)) return {};
  std::string text = std::string(spec.name) + " must be " + spec.range.text();
  if (*spec.unit != '\0') text += std::string(" ") + spec.unit;
  return text + ", got " + number(value);
}

std::vector<std::string> choiceWords(const std::string& choices) {
  std::vector<std::string> words;
  if (choices.empty()) return words;
  for (size_t start = 0; start <= choices.size();) {
    const size_t end = std::min(choices.find('|', start), choices.size());
    words.push_back(choices.substr(start, end - start));
    start = end + 1;
  }
  return words;
}

std::string choiceProblem(const ParamSpec& spec, const std::string& value) {
  const std::vector<std::string> words = choiceWords(spec.choices);
  if (words.empty()) return {};
  std::string list;
  for (const std::string& word : words) {
    if (word == value) return {};
    list += (list.empty() ? "" : ", ") + word;
  }
  return std::string(spec.name) + " must be one of " + list + ", got '" + value + "'";
}

std::string formatParamDouble(double v) {
  char buf[64];
  const auto result = std::to_chars(buf, buf + sizeof(buf), v);
  std::string s(buf, result.ptr);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";  // keep it a real number
  return s;
}

}  // namespace lidar_stereo_fusion
