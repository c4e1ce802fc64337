// The tools' command line (kitti_runner, fusion_benchmark, accuracy_report, kitti_to_bag, ...): a
// small parser, and the one shape of their main (toolMain). ROS-free.
#pragma once

#include <functional>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace lidar_stereo_fusion {

/// Bad command line: the tool prints the message and its usage and exits with status 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// "--name value" options and "--name" flags. Every argument must be declared; anything else, a
/// repeated option or an option without its value is a UsageError.
class CommandLine {
 public:
  /// `options` take a value, `flags` do not (names with the leading "--").
  CommandLine(int argc, const char* const* argv, const std::set<std::string>& options,
              const std::set<std::string>& flags);

  bool has(const std::string& name) const;
  /// The option's value, or `fallback` when it was not given.
  std::string value(const std::string& name, const std::string& fallback = "") const;
  /// The option's value as an integer in [min, max]; UsageError naming the option otherwise.
  int intValue(const std::string& name, int fallback, int min, int max) const;
  /// The option's value as a finite number in [min, max]; UsageError naming the option otherwise.
  double doubleValue(const std::string& name, double fallback, double min, double max) const;
  /// The option's value, which must be one of `choices`.
  std::string choice(const std::string& name, const std::string& fallback,
                     const std::vector<std::string>& choices) const;

 private:
  std::map<std::string, std::string> values_;
  std::set<std::string> flags_;
};

/// True when an argument is "--help" or "-h".
bool wantsHelp(int argc, const char* const* argv);

/// The main of every tool: with --help or -h, prints `usage` on stdout and returns 0; otherwise
/// returns what `run` returns (it reads the command line and does the work). A UsageError, thrown
/// while reading the command line or later, prints "<name>: <message>", a blank line and `usage`
/// on stderr and returns 2; any other exception prints "<name>: error: <message>" on stderr and
/// returns 1.
int toolMain(const std::string& name, const std::string& usage, int argc, const char* const* argv,
             const std::function<int()>& run);

}  // namespace lidar_stereo_fusion
