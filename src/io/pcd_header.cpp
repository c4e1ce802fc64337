// PCD header: the checks of every header line, in front of PCL's reader (pcd.cpp).
#include "pcd_header.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace lidar_stereo_fusion {
namespace pcd {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error("PCD " + path + ": " + what);
}

std::vector<std::string> splitWords(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> words;
  std::string word;
  while (in >> word) words.push_back(word);
  return words;
}

namespace {

long long parseInteger(const std::string& path, const std::string& key, const std::string& text) {
  char* end = nullptr;
  errno = 0;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  if (end == text.c_str() || *end != '\0' || errno == ERANGE) {
    fail(path, "header " + key + " has a non-integer value '" + text + "'");
  }
  return value;
}

/// An int-sized header value (SIZE, COUNT, WIDTH, HEIGHT) in [0, INT_MAX].
int parseCount(const std::string& path, const std::string& key, const std::string& text) {
  const long long value = parseInteger(path, key, text);
  if (value < 0 || value > std::numeric_limits<int>::max()) {
    fail(path, "header " + key + " value " + text + " is out of range");
  }
  return static_cast<int>(value);
}

/// A header is ASCII text: PCL 1.13's reader crashed (SIGSEGV) on a header line holding a NUL
/// byte (found by fuzz/fuzz_pcd.cpp), so control and non-ASCII bytes are refused before PCL sees
/// the file.
void requireText(const std::string& path, const std::string& line, int number) {
  for (const char c : line) {
    const auto byte = static_cast<unsigned char>(c);
    if ((byte < 0x20 && c != '\t') || byte > 0x7e) {
      fail(path, "header line " + std::to_string(number) + " holds byte " + std::to_string(byte) +
                     " (a PCD header is ASCII text; binary data before DATA?)");
    }
  }
}

/// A value of one of WIDTH, HEIGHT, POINTS: exactly one.
const std::string& single(const std::string& path, const std::string& key,
                          const std::vector<std::string>& values) {
  if (values.size() != 1) {
    fail(path, "header " + key + " has " + std::to_string(values.size()) + " values, not one");
  }
  return values[0];
}

void parseViewpoint(const std::string& path, const std::vector<std::string>& values) {
  bool numbers = values.size() == 7;
  for (const std::string& v : values) {
    char* end = nullptr;
    std::strtod(v.c_str(), &end);
    numbers = numbers && end != v.c_str() && *end == '\0';
  }
  if (!numbers) fail(path, "header VIEWPOINT needs 7 numbers (tx ty tz qw qx qy qz)");
}

/// The place of a header key in the order the PCD format fixes (PCL's reader refuses another
/// order), or -1 for a key it does not know.
int keyRank(const std::string& key) {
  static const char* const kOrder[] = {"VERSION", "FIELDS", "SIZE",      "TYPE",   "COUNT",
                                       "WIDTH",   "HEIGHT", "VIEWPOINT", "POINTS", "DATA"};
  const std::string name = key == "COLUMNS" ? "FIELDS" : key;
  for (int i = 0; i < 10; ++i) {
    if (name == kOrder[i]) return i;
  }
  return -1;
}

/// Reads one header line's key and values into `header`; true at DATA. PCL's reader stops at
/// the first line it does not know and then reads the file without POINTS (it crashed on such a
/// file, found by fuzzing): every line must be one it knows, a comment or empty.
bool parseHeaderLine(const std::string& path, const std::vector<std::string>& words, Header& header,
                     bool& have_points) {
  const std::string& key = words[0];
  const std::vector<std::string> values(words.begin() + 1, words.end());
  if (key == "VERSION") {
    header.version = values.empty() ? "" : values[0];
  } else if (key == "FIELDS" || key == "COLUMNS") {
    header.fields = values;
  } else if (key == "SIZE") {
    for (const auto& v : values) header.sizes.push_back(parseCount(path, key, v));
  } else if (key == "TYPE") {
    for (const auto& v : values) {
      if (v.size() != 1 || (v[0] != 'F' && v[0] != 'I' && v[0] != 'U')) {
        fail(path, "header TYPE '" + v + "' is not F, I or U");
      }
      header.types.push_back(v[0]);
    }
  } else if (key == "COUNT") {
    for (const auto& v : values) header.counts.push_back(parseCount(path, key, v));
  } else if (key == "WIDTH") {
    header.width = parseCount(path, key, single(path, key, values));
  } else if (key == "HEIGHT") {
    header.height = parseCount(path, key, single(path, key, values));
  } else if (key == "POINTS") {
    const long long points = parseInteger(path, key, single(path, key, values));
    if (points < 0) fail(path, "header POINTS is negative");
    header.points = static_cast<std::size_t>(points);
    have_points = true;
  } else if (key == "VIEWPOINT") {
    parseViewpoint(path, values);  // checked, not used: points stay in the file's frame
  } else if (key == "DATA") {
    header.data = values.empty() ? "" : values[0];
    return true;
  } else {
    fail(path, "header has an unknown line '" + key +
                   " ...' (a PCD header holds VERSION, "
                   "FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS, DATA)");
  }
  return false;
}

/// Parses header lines up to and including DATA; leaves `in` at the first data byte.
}  // namespace

Header readHeader(std::istream& in, const std::string& path) {
  Header header;
  bool have_points = false;
  std::string line;
  int number = 0;
  int last_rank = -1;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    requireText(path, line, number);
    if (line.empty()) continue;
    const std::vector<std::string> words = splitWords(line);
    if (words.empty()) {
      fail(path, "header line " + std::to_string(number) + " holds only blanks");
    }
    if (words[0][0] == '#') continue;
    const int rank = keyRank(words[0]);
    if (rank >= 0 && rank <= last_rank) {
      fail(path, "header line " + std::to_string(number) + " (" + words[0] +
                     ") is out of order or repeated (a PCD header holds VERSION, FIELDS, SIZE, "
                     "TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS, DATA in this order)");
    }
    last_rank = rank;
    if (parseHeaderLine(path, words, header, have_points)) break;
  }
  if (header.data.empty()) fail(path, "no DATA line (not a PCD file, or truncated header)");
  if (header.fields.empty()) fail(path, "header has no FIELDS");
  const std::size_t n = header.fields.size();
  if (header.counts.empty()) header.counts.assign(n, 1);
  if (header.sizes.size() != n || header.types.size() != n || header.counts.size() != n) {
    fail(path, "header FIELDS, SIZE, TYPE and COUNT have different lengths");
  }
  for (std::size_t i = 0; i < n; ++i) {
    const int size = header.sizes[i];
    const bool ok = header.types[i] == 'F' ? (size == 4 || size == 8)
                                           : (size == 1 || size == 2 || size == 4 || size == 8);
    if (!ok) {
      fail(path, "field '" + header.fields[i] + "' has unsupported TYPE " +
                     std::string(1, header.types[i]) + " with SIZE " + std::to_string(size));
    }
    if (header.counts[i] < 1 || header.counts[i] > (1 << 20)) {
      fail(path, "field '" + header.fields[i] + "' has COUNT " + std::to_string(header.counts[i]) +
                     " (expected 1 .. 2^20)");
    }
  }
  if (header.height == 0) header.height = 1;
  const std::size_t grid = static_cast<std::size_t>(header.width) * header.height;
  if (!have_points) fail(path, "header has no POINTS");
  if (header.points != grid) {
    fail(path, "header POINTS (" + std::to_string(header.points) + ") != WIDTH * HEIGHT (" +
                   std::to_string(grid) + ")");
  }
  return header;
}

/// Where the fields we use sit within one point.

}  // namespace pcd
}  // namespace lidar_stereo_fusion
