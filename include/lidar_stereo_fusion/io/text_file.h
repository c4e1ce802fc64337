// Text files handed to OpenCV's FileStorage (parameters, calibrations). ROS-free.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace lidar_stereo_fusion {

/// The whole file at `path`; std::runtime_error "<what>: cannot open <path>" when unreadable.
std::string readTextFile(const std::string& path, const std::string& what);

/// Calls f(number, line) for each line of `text`, numbered from 1, without its '\n' (a '\r'
/// before it stays). A last line without '\n' is a line; an empty text has none.
template <typename F>
void forEachLine(std::string_view text, F&& f) {
  std::size_t start = 0;
  for (int number = 1; start < text.size(); ++number) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    f(number, text.substr(start, end - start));
    start = end + 1;
  }
}

/// Throws std::runtime_error "<what> <path>: not a text file (control byte B at offset N)" when
/// `text` has control bytes other than tab, CR and LF. OpenCV reads a buffer only up to its first
/// NUL (binary garbage would load as an empty file) and its YAML parser can loop forever on some
/// binary input (found by fuzzing the Autoware reader), so such files never reach it.
void requireTextFile(const std::string& text, const std::string& path, const std::string& what);

/// Throws std::runtime_error "<what> <path> line N: ..." when a YAML document marker ("---" or
/// "...", after any indentation) has anything but blanks or a comment after it on its line.
/// OpenCV 4.6's YAML parser loops forever on some such files: a collection that begins on the
/// marker's line ends at the next less indented line, and the parser then skips three characters
/// as if they were a marker; a lone '-' there makes its search for the next document spin
/// without advancing (found by fuzzing the parameter reader: "---hod: pms\npat-hod: pms\nc: 1").
/// Also when anything but blanks, comments or a "---" follows a "..." (document end): the parser
/// loops the same way on a '-' there ("...\n-", found by fuzzing too).
void requireYamlMarkersAlone(const std::string& text, const std::string& path,
                             const std::string& what);

}  // namespace lidar_stereo_fusion
