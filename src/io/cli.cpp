// Command-line parsing and the main of the tools.
#include "lidar_stereo_fusion/io/cli.h"

#include <climits>
#include <cmath>
#include <iostream>
#include <sstream>

namespace lidar_stereo_fusion {

CommandLine::CommandLine(int argc, const char* const* argv, const std::set<std::string>& options,
                         const std::set<std::string>& flags) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (flags.count(arg) > 0) {
      if (!flags_.insert(arg).second) throw UsageError(arg + " given twice");
    } else if (options.count(arg) > 0) {
      if (i + 1 >= argc) throw UsageError(arg + " needs a value");
      if (values_.count(arg) > 0) throw UsageError(arg + " given twice");
      values_[arg] = argv[++i];
    } else {
      throw UsageError("unknown argument '" + arg + "'");
    }
  }
}

bool CommandLine::has(const std::string& name) const {
  return flags_.count(name) > 0 || values_.count(name) > 0;
}

std::string CommandLine::value(const std::string& name, const std::string& fallback) const {
  const auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second;
}

namespace {

/// Whether `parse` (std::stol, std::stod) reads all of `text`; the number goes to `out`.
template <class T, class Parse>
bool readWhole(const std::string& text, Parse parse, T& out) {
  size_t used = 0;
  try {
    out = parse(text, &used);
  } catch (const std::exception&) {
    return false;
  }
  return used != 0 && used == text.size();
}

}  // namespace

int CommandLine::intValue(const std::string& name, int fallback, int min, int max) const {
  const auto it = values_.find(name);
  if (it == values_.end()) return fallback;
  long parsed = 0;
  const auto parse = [](const std::string& t, size_t* used) { return std::stol(t, used); };
  if (!readWhole(it->second, parse, parsed) || parsed < min || parsed > max) {
    throw UsageError(name + " must be an integer in [" + std::to_string(min) + ", " +
                     std::to_string(max) + "], got '" + it->second + "'");
  }
  return static_cast<int>(parsed);
}

double CommandLine::doubleValue(const std::string& name, double fallback, double min,
                                double max) const {
  const auto it = values_.find(name);
  if (it == values_.end()) return fallback;
  double parsed = 0.0;
  const auto parse = [](const std::string& t, size_t* used) { return std::stod(t, used); };
  if (!readWhole(it->second, parse, parsed) || !std::isfinite(parsed) || parsed < min ||
      parsed > max) {
    std::ostringstream range;
    range << "[" << min << ", " << max << "]";
    throw UsageError(name + " must be a number in " + range.str() + ", got '" + it->second + "'");
  }
  return parsed;
}

std::string CommandLine::choice(const std::string& name, const std::string& fallback,
                                const std::vector<std::string>& choices) const {
  const std::string v = value(name, fallback);
  std::string valid;
  for (const std::string& c : choices) {
    if (c == v) return v;
    valid += (valid.empty() ? "" : ", ") + c;
  }
  throw UsageError(name + " must be one of " + valid + ", got '" + v + "'");
}

bool wantsHelp(int argc, const char* const* argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") return true;
  }
  return false;
}

int toolMain(const std::string& name, const std::string& usage, int argc, const char* const* argv,
             const std::function<int()>& run) {
  if (wantsHelp(argc, argv)) {
    std::cout << usage;
    return 0;
  }
  try {
    return run();
  } catch (const UsageError& e) {
    std::cerr << name << ": " << e.what() << "\n\n" << usage;
    return 2;
  } catch (const std::exception& e) {
    std::cerr << name << ": error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace lidar_stereo_fusion
