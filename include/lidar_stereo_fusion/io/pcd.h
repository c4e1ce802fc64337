// Reading and writing PCD files with PCL's reader and writer. ROS-free.
//
// Supported: PCD v0.7 (and v0.6 without VIEWPOINT), DATA ascii, binary and binary_compressed
// (LZF), organised or not, any field types F (4, 8 bytes), I and U (1, 2, 4, 8 bytes) with
// COUNT >= 1. Binary data is in the host byte order (little-endian on every platform we build
// for), as PCL writes it. VIEWPOINT is ignored: points are returned in the file's frame.
// This package parses the header and checks the data's size (and every ascii value) before PCL
// reads the file, so that a bad file is refused with a message naming the problem: PCL alone
// accepts ascii words that are no numbers and lines with missing values, and crashed on headers
// with a NUL byte or an unknown line (test/core/test_pcd_pcl.cpp, doc/libraries.md).
#pragma once

#include <string>
#include <vector>

#include "lidar_stereo_fusion/core/depth.h"
#include "lidar_stereo_fusion/core/types.h"

namespace lidar_stereo_fusion {
namespace pcd {

/// The header of a PCD file.
struct Header {
  std::string version;              ///< e.g. "0.7"
  std::vector<std::string> fields;  ///< FIELDS, e.g. {"x", "y", "z", "intensity", "ring"}
  std::vector<int> sizes;           ///< SIZE of each field [bytes]
  std::vector<char> types;          ///< TYPE of each field: 'F', 'I' or 'U'
  std::vector<int> counts;          ///< COUNT of each field (elements)
  int width = 0, height = 0;        ///< WIDTH, HEIGHT
  std::size_t points = 0;           ///< POINTS (= width * height)
  std::string data;                 ///< "ascii", "binary" or "binary_compressed"

  /// True when the header has a field of that name.
  bool hasField(const std::string& name) const;
};

/// Reads a PCD file into LiDAR points. Fields used: x, y, z [m] (required), intensity, ring
/// (rounded to an integer; -1 when absent), time [s] (when present). Other fields are skipped; a
/// field with COUNT > 1 contributes its first element. Non-finite points are kept (an organised
/// cloud marks missing returns with NaN); later stages skip them. If `header` is given it receives
/// the parsed header. Throws std::runtime_error naming the file and the problem (unreadable file,
/// malformed or inconsistent header (not ASCII, an unknown line, no POINTS, ...), missing x/y/z,
/// truncated or corrupt data, unknown DATA).
LidarCloud readPcd(const std::string& path, Header* header = nullptr);

/// The DATA kinds of a PCD file.
enum class DataKind { kAscii, kBinary, kBinaryCompressed };

/// Writes x y z intensity (float32), ring (uint16, only when every point has ring >= 0) and time
/// (float32) as PCD v0.7 with PCL's writer. Throws std::runtime_error when writing fails.
void writePcd(const std::string& path, const LidarCloud& cloud, DataKind data);

/// writePcd with DATA binary (`binary`) or ascii.
void writePcd(const std::string& path, const LidarCloud& cloud, bool binary = true);

/// Writes coloured points (e.g. makeColoredCloud of a depth map: [m], left optical frame) with
/// PCL's writer as PCD v0.7, DATA binary_compressed, fields x y z rgb (PCL's PointXYZRGB: rgb
/// packed 0x00RRGGBB in a float), WIDTH = number of points, HEIGHT 1, in the order given.
/// Readable by pcl_viewer and PCL's converters. Throws std::runtime_error when writing fails.
void writeColoredPcd(const std::string& path, const std::vector<ColoredPoint>& points);

}  // namespace pcd
}  // namespace lidar_stereo_fusion
