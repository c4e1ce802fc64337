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
  int document_end = 0;  // the line of the last '...' while no '---' has followed it
  forEachLine(text, [&](int number, std::string_view line) {
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string_view::npos || line[first] == '#') return;
    const std::string_view marker = line.substr(first, 3);
    if (marker != "---" && marker != "...") {
      if (document_end > 0) {
        throw std::runtime_error(what + " " + path + " line " + std::to_string(number) +
                                 ": content after the document end '...' of line " +
                                 std::to_string(document_end) +
                                 " (a new YAML document starts with '---')");
      }
      return;
    }
    const std::size_t rest = line.find_first_not_of(" \t\r", first + 3);
    if (rest != std::string_view::npos && line[rest] != '#') {
      throw std::runtime_error(what + " " + path + " line " + std::to_string(number) + ": '" +
                               std::string(marker) +
                               "' (a YAML document marker) must be alone on its line");
    }
    document_end = marker == "..." ? number : 0;
  });
}

}  // namespace lidar_stereo_fusion
