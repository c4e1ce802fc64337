// PCD header parsing and the readers' error wording, shared by pcd.cpp (private to src/io).
#pragma once

#include <istream>
#include <string>
#include <vector>

#include "lidar_stereo_fusion/io/pcd.h"

namespace lidar_stereo_fusion {
namespace pcd {

/// Throws std::runtime_error "PCD <path>: <what>".
[[noreturn]] void fail(const std::string& path, const std::string& what);

/// The whitespace-separated words of `text`.
std::vector<std::string> splitWords(const std::string& text);

/// Reads and checks the header lines up to and including DATA; `in` is left at the first byte of
/// the data. Throws std::runtime_error naming the line and the problem.
Header readHeader(std::istream& in, const std::string& path);

}  // namespace pcd
}  // namespace lidar_stereo_fusion
