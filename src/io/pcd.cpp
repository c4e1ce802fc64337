// PCD reader: the header checked in pcd_header.cpp, the body checked and decoded here (PCL's LZF
// codec for binary_compressed; why not PCL's PCDReader: readCompressedBody).
#include "lidar_stereo_fusion/io/pcd.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <pcl/io/lzf.h>

#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "pcd_header.h"

namespace lidar_stereo_fusion {
namespace pcd {
namespace {

struct Layout {
  int x = -1, y = -1, z = -1, intensity = -1, ring = -1, time = -1;  ///< field index or -1
  std::vector<std::size_t> offset;  ///< byte offset of each field in a binary record
  std::vector<std::size_t> column;  ///< token index of each field in an ascii line
  std::size_t stride = 0;           ///< bytes per binary record
  std::size_t tokens = 0;           ///< numbers per ascii line
};

Layout makeLayout(const Header& header, const std::string& path) {
  Layout layout;
  for (std::size_t i = 0; i < header.fields.size(); ++i) {
    const std::string& name = header.fields[i];
    const int index = static_cast<int>(i);
    if (name == "x") layout.x = index;
    if (name == "y") layout.y = index;
    if (name == "z") layout.z = index;
    if (name == "intensity") layout.intensity = index;
    if (name == "ring") layout.ring = index;
    if (name == "time") layout.time = index;
    layout.offset.push_back(layout.stride);
    layout.column.push_back(layout.tokens);
    layout.stride += static_cast<std::size_t>(header.sizes[i]) * header.counts[i];
    layout.tokens += header.counts[i];
  }
  if (layout.x < 0 || layout.y < 0 || layout.z < 0) fail(path, "fields x, y and z are required");
  return layout;
}

template <typename T>
double load(const unsigned char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return static_cast<double>(value);
}

double decodeBinary(const unsigned char* p, char type, int size) {
  if (type == 'F') return size == 4 ? load<float>(p) : load<double>(p);
  if (type == 'I') {
    switch (size) {
      case 1:
        return load<int8_t>(p);
      case 2:
        return load<int16_t>(p);
      case 4:
        return load<int32_t>(p);
      default:
        return load<int64_t>(p);
    }
  }
  switch (size) {
    case 1:
      return load<uint8_t>(p);
    case 2:
      return load<uint16_t>(p);
    case 4:
      return load<uint32_t>(p);
    default:
      return load<uint64_t>(p);
  }
}

/// Fills one point from a getter value(field index) -> double.
template <typename Getter>
LidarPoint makePoint(const Layout& layout, Getter value) {
  LidarPoint point;
  point.x = static_cast<float>(value(layout.x));
  point.y = static_cast<float>(value(layout.y));
  point.z = static_cast<float>(value(layout.z));
  if (layout.intensity >= 0) point.intensity = static_cast<float>(value(layout.intensity));
  if (layout.ring >= 0) {
    const double ring = value(layout.ring);
    point.ring = std::isfinite(ring) && ring >= 0.0 && ring <= std::numeric_limits<int>::max()
                     ? static_cast<int>(std::lround(ring))
                     : -1;
  }
  if (layout.time >= 0) point.time = static_cast<float>(value(layout.time));
  return point;
}

/// Bytes from the current position of `in` to its end.
std::size_t remainingBytes(std::istream& in) {
  const std::streampos here = in.tellg();
  in.seekg(0, std::ios::end);
  const std::streampos end = in.tellg();
  in.seekg(here);
  return here < 0 || end < here ? 0 : static_cast<std::size_t>(end - here);
}

void checkBinary(std::istream& in, const Header& header, const Layout& layout,
                 const std::string& path) {
  const std::size_t available = remainingBytes(in);
  if (header.points > available / layout.stride) {
    fail(path, "binary data is truncated: " + std::to_string(header.points) + " points of " +
                   std::to_string(layout.stride) + " bytes need more than the " +
                   std::to_string(available) + " bytes left");
  }
}

/// The two size words in front of LZF data: PCL checks them too, but only says "corrupted"; these
/// messages name the numbers, and an impossible size is refused before anything is allocated.
uint32_t checkCompressed(std::istream& in, const Header& header, const Layout& layout,
                         const std::string& path) {
  const std::size_t available = remainingBytes(in);
  uint32_t sizes[2] = {0, 0};  // compressed, uncompressed [bytes]
  if (available < sizeof(sizes)) {
    fail(path, "DATA binary_compressed is truncated: no compressed and uncompressed sizes");
  }
  in.read(reinterpret_cast<char*>(sizes), sizeof(sizes));
  if (sizes[0] > available - sizeof(sizes)) {
    fail(path, "DATA binary_compressed is truncated: " + std::to_string(sizes[0]) +
                   " compressed bytes announced, " + std::to_string(available - sizeof(sizes)) +
                   " left");
  }
  const uint64_t expected = static_cast<uint64_t>(header.points) * layout.stride;
  if (sizes[1] != expected) {
    fail(path, "DATA binary_compressed: uncompressed size " + std::to_string(sizes[1]) +
                   " bytes, but " + std::to_string(header.points) + " points of " +
                   std::to_string(layout.stride) + " bytes need " + std::to_string(expected));
  }
  // An LZF back reference (3 bytes) expands to at most 264 bytes.
  constexpr uint64_t kLzfMaxRatio = 88;
  if (expected > kLzfMaxRatio * sizes[0] + kLzfMaxRatio) {
    fail(path, "DATA binary_compressed: " + std::to_string(sizes[0]) +
                   " compressed bytes cannot hold " + std::to_string(expected) + " bytes");
  }
  return sizes[0];
}

/// DATA ascii, read and checked here: PCL's reader reports success with 0 for a word that is no
/// number ("1 2 x") and for missing values ("1 2" under three fields); see
/// test/io/test_pcd_pcl.cpp, Pcl* tests. A field's first value is its value (as in binary).
LidarCloud readAsciiBody(std::istream& in, const Header& header, const Layout& layout,
                         const std::string& path) {
  LidarCloud out;
  std::vector<double> values(layout.tokens);
  std::string line;
  while (out.size() < header.points && std::getline(in, line)) {
    const std::vector<std::string> words = splitWords(line);
    if (words.empty()) continue;
    const std::string point = std::to_string(out.size());
    if (words.size() != layout.tokens) {
      fail(path, "ascii point " + point + " has " + std::to_string(words.size()) +
                     " values, the header says " + std::to_string(layout.tokens));
    }
    for (std::size_t k = 0; k < words.size(); ++k) {
      char* end = nullptr;
      values[k] = std::strtod(words[k].c_str(), &end);
      if (end == words[k].c_str() || *end != '\0') {
        fail(path, "ascii point " + point + " has a non-number '" + words[k] + "'");
      }
    }
    out.push_back(makePoint(layout, [&](int f) { return values[layout.column[f]]; }));
  }
  if (out.size() != header.points) {
    fail(path, "ascii data is truncated: " + std::to_string(out.size()) + " of " +
                   std::to_string(header.points) + " points");
  }
  return out;
}

/// The points of `points` records of layout.stride bytes.
LidarCloud decodeRecords(const unsigned char* data, std::size_t points, const Header& header,
                         const Layout& layout) {
  LidarCloud out;
  out.reserve(points);
  for (std::size_t i = 0; i < points; ++i) {
    const unsigned char* record = data + i * layout.stride;
    out.push_back(makePoint(layout, [&](int f) {
      return decodeBinary(record + layout.offset[f], header.types[f], header.sizes[f]);
    }));
  }
  return out;
}

/// DATA binary, read here: PCL 1.13's PCDReader::readBodyBinary reads out of bounds on some
/// bodies that pass checkBinary (found by fuzz_pcd), and a binary body is only the records.
LidarCloud readBinaryBody(std::istream& in, const Header& header, const Layout& layout,
                          const std::string& path) {
  std::vector<unsigned char> data(header.points * layout.stride);
  in.read(reinterpret_cast<char*>(data.data()), static_cast<std::streamsize>(data.size()));
  if (static_cast<std::size_t>(in.gcount()) != data.size()) {
    fail(path, "binary data is truncated");
  }
  return decodeRecords(data.data(), header.points, header, layout);
}

/// DATA binary_compressed: PCL's LZF codec (pcl::lzfDecompress), the records decoded here. PCL
/// 1.13's PCDReader is not used for any body: it crashed on fuzzed files that passed every check
/// above (ascii and binary bodies, header lines; found by fuzz/fuzz_pcd.cpp in CI runs).
/// PCL writes the decompressed bytes field by field: all points' x, then all y, ...
LidarCloud readCompressedBody(std::istream& in, const Header& header, const Layout& layout,
                              const std::string& path) {
  const uint32_t compressed = checkCompressed(in, header, layout, path);
  const std::size_t bytes = header.points * layout.stride;
  if (bytes == 0) return {};
  std::vector<unsigned char> packed(compressed);
  in.read(reinterpret_cast<char*>(packed.data()), static_cast<std::streamsize>(packed.size()));
  std::vector<unsigned char> data(bytes);
  const unsigned int got =
      pcl::lzfDecompress(packed.data(), compressed, data.data(), static_cast<unsigned int>(bytes));
  if (static_cast<std::size_t>(in.gcount()) != packed.size() || got != bytes) {
    fail(path, "DATA binary_compressed: the LZF data is corrupt (" + std::to_string(got) + " of " +
                   std::to_string(bytes) + " bytes decompressed)");
  }
  LidarCloud out;
  out.reserve(header.points);
  for (std::size_t i = 0; i < header.points; ++i) {
    out.push_back(makePoint(layout, [&](int f) {
      const std::size_t field_bytes = static_cast<std::size_t>(header.sizes[f]) * header.counts[f];
      const unsigned char* p = data.data() + header.points * layout.offset[f] + i * field_bytes;
      return decodeBinary(p, header.types[f], header.sizes[f]);
    }));
  }
  return out;
}

}  // namespace

bool Header::hasField(const std::string& name) const {
  return std::find(fields.begin(), fields.end(), name) != fields.end();
}

LidarCloud readPcd(const std::string& path, Header* header_out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open file");
  const Header header = readHeader(in, path);
  const Layout layout = makeLayout(header, path);
  if (header_out) *header_out = header;
  if (header.data == "binary") {
    checkBinary(in, header, layout, path);
    return readBinaryBody(in, header, layout, path);
  }
  if (header.data == "binary_compressed") return readCompressedBody(in, header, layout, path);
  if (header.data == "ascii") return readAsciiBody(in, header, layout, path);
  fail(path, "unknown DATA '" + header.data + "' (expected ascii, binary or binary_compressed)");
}

}  // namespace pcd
}  // namespace lidar_stereo_fusion
