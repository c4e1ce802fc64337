// Reading and writing PCD (Point Cloud Library) files without PCL. ROS-free.
//
// Supported: PCD v0.7 (and v0.6 without VIEWPOINT), DATA ascii and binary, organised or not, any
// field types F (4, 8 bytes), I and U (1, 2, 4, 8 bytes) with COUNT >= 1. Binary data is read in
// the host byte order (little-endian on every platform we build for), as PCL writes it.
// DATA binary_compressed (LZF) is rejected with a clear message. VIEWPOINT is ignored: points are
// returned in the file's frame.
#pragma once

#include <string>
#include <vector>

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
  std::string data;                 ///< "ascii" or "binary"

  /// True when the header has a field of that name.
  bool hasField(const std::string& name) const;
};

/// Reads a PCD file into LiDAR points. Fields used: x, y, z [m] (required), intensity, ring
/// (rounded to an integer; -1 when absent), time [s] (when present). Other fields are skipped; a
/// field with COUNT > 1 contributes its first element. Non-finite points are kept (an organised
/// cloud marks missing returns with NaN); later stages skip them. If `header` is given it receives
/// the parsed header. Throws std::runtime_error naming the file and the problem (unreadable file,
/// malformed or inconsistent header, missing x/y/z, truncated data, unsupported DATA).
LidarCloud readPcd(const std::string& path, Header* header = nullptr);

/// Writes x y z intensity (float32), ring (uint16, only when every point has ring >= 0) and time
/// (float32) as PCD v0.7, `binary` or ascii. Throws std::runtime_error when writing fails.
void writePcd(const std::string& path, const LidarCloud& cloud, bool binary = true);

}  // namespace pcd
}  // namespace lidar_stereo_fusion
