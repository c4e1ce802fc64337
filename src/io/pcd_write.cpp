// PCD writers: LiDAR sweeps and coloured clouds through PCL's writer.
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/io/pcd.h"

namespace lidar_stereo_fusion {
namespace pcd {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error("PCD " + path + ": " + what);
}

/// x y z intensity [ring] time as a PCLPointCloud2 (ring only when every point has one).
pcl::PCLPointCloud2 toPclCloud(const LidarCloud& cloud, const std::string& path) {
  const bool with_ring = !cloud.empty() && hasRings(cloud);
  pcl::PCLPointCloud2 out;
  auto add = [&out](const std::string& name, uint8_t datatype, uint32_t size) {
    pcl::PCLPointField field;
    field.name = name;
    field.offset = out.point_step;
    field.datatype = datatype;
    field.count = 1;
    out.fields.push_back(field);
    out.point_step += size;
  };
  for (const char* name : {"x", "y", "z", "intensity"}) add(name, pcl::PCLPointField::FLOAT32, 4);
  if (with_ring) add("ring", pcl::PCLPointField::UINT16, 2);
  add("time", pcl::PCLPointField::FLOAT32, 4);
  out.width = static_cast<uint32_t>(cloud.size());
  out.height = 1;
  out.row_step = out.point_step * out.width;
  out.is_dense = false;
  out.data.resize(static_cast<std::size_t>(out.row_step));
  unsigned char* p = out.data.data();
  for (const LidarPoint& point : cloud) {
    const float xyzi[4] = {point.x, point.y, point.z, point.intensity};
    std::memcpy(p, xyzi, sizeof(xyzi));
    p += sizeof(xyzi);
    if (with_ring) {
      if (point.ring > std::numeric_limits<uint16_t>::max()) {
        fail(path, "ring " + std::to_string(point.ring) + " does not fit uint16");
      }
      const uint16_t ring = static_cast<uint16_t>(point.ring);
      std::memcpy(p, &ring, sizeof(ring));
      p += sizeof(ring);
    }
    std::memcpy(p, &point.time, sizeof(point.time));
    p += sizeof(point.time);
  }
  return out;
}

int writeWithPcl(const std::string& path, const pcl::PCLPointCloud2& cloud, DataKind data) {
  pcl::PCDWriter writer;
  const Eigen::Vector4f origin = Eigen::Vector4f::Zero();
  const Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();
  try {
    switch (data) {
      case DataKind::kAscii:
        return writer.writeASCII(path, cloud, origin, orientation,
                                 std::numeric_limits<float>::max_digits10);
      case DataKind::kBinary:
        return writer.writeBinary(path, cloud, origin, orientation);
      default:
        return writer.writeBinaryCompressed(path, cloud, origin, orientation);
    }
  } catch (const std::exception& e) {  // pcl::IOException
    fail(path, std::string("PCL's writer: ") + e.what());
  }
}

}  // namespace

void writePcd(const std::string& path, const LidarCloud& cloud, DataKind data) {
  if (writeWithPcl(path, toPclCloud(cloud, path), data) < 0) fail(path, "write failed");
}

void writePcd(const std::string& path, const LidarCloud& cloud, bool binary) {
  writePcd(path, cloud, binary ? DataKind::kBinary : DataKind::kAscii);
}

void writeColoredPcd(const std::string& path, const std::vector<ColoredPoint>& points) {
  pcl::PointCloud<pcl::PointXYZRGB> cloud;
  cloud.reserve(points.size());
  for (const ColoredPoint& p : points) {
    pcl::PointXYZRGB q(p.r, p.g, p.b);
    q.x = p.x;
    q.y = p.y;
    q.z = p.z;
    cloud.push_back(q);
  }
  int status = -1;
  try {
    status = pcl::PCDWriter().writeBinaryCompressed(path, cloud);
  } catch (const std::exception& e) {  // pcl::IOException
    fail(path, std::string("PCL's writer: ") + e.what());
  }
  if (status < 0) fail(path, "write failed");
}

}  // namespace pcd
}  // namespace lidar_stereo_fusion
