// Text files handed to OpenCV's FileStorage (text_file.h).
#include "lidar_stereo_fusion/io/text_file.h"

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace lidar_stereo_fusion {

std::string readTextFile(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(what + ": cannot open " + path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

void requireTextFile(const std::string& text, const std::string& path, const std::string& what) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 && c != '\t' && c != '\n' && c != '\r') {
      throw std::runtime_error(what + " " + path + ": not a text file (control byte " +
                               std::to_string(c) + " at offset " + std::to_string(i) + ")");
    }
  }
}

void requireYamlMarkersAlone(const std::string& text, const std::string& path,
                             const std::string& what) {
  std::size_t line_start = 0;
  for (int line = 1; line_start < text.size(); ++line) {
    std::size_t line_end = text.find('\n', line_start);
    if (line_end == std::string::npos) line_end = text.size();
    const std::size_t first = text.find_first_not_of(" \t", line_start);
    if (first < line_end &&
        (text.compare(first, 3, "---") == 0 || text.compare(first, 3, "...") == 0)) {
      const std::size_t rest = text.find_first_not_of(" \t\r", first + 3);
      if (rest < line_end && text[rest] != '#') {
        throw std::runtime_error(what + " " + path + " line " + std::to_string(line) + ": '" +
                                 text.substr(first, 3) +
                                 "' (a YAML document marker) must be alone on its line");
      }
    }
    line_start = line_end + 1;
  }
}

}  // namespace lidar_stereo_fusion
