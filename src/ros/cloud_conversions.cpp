// PointCloud2 input (and the velodyne_pointcloud layout written back for tests and tools): the
// layout checks where a sweep enters, and the per-point time fields of the common drivers.
//
// Why not pcl::fromROSMsg: it copies fields by name and offset without comparing the message's
// declared layout (offsets, point_step, row_step) with the size of its data, so a malformed cloud
// is read past its buffer; here every offset is checked against point_step and the data size first.
#include "lidar_stereo_fusion/ros/conversions.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>

#include <sensor_msgs/point_cloud2_iterator.h>

namespace lidar_stereo_fusion {
namespace conversions {

namespace {

using sensor_msgs::PointField;

int datatypeSize(uint8_t datatype) {
  switch (datatype) {
    case PointField::INT8:
    case PointField::UINT8:
      return 1;
    case PointField::INT16:
    case PointField::UINT16:
      return 2;
    case PointField::INT32:
    case PointField::UINT32:
    case PointField::FLOAT32:
      return 4;
    case PointField::FLOAT64:
      return 8;
    default:
      return 0;
  }
}

const char* datatypeName(uint8_t datatype) {
  switch (datatype) {
    case PointField::INT8:
      return "INT8";
    case PointField::UINT8:
      return "UINT8";
    case PointField::INT16:
      return "INT16";
    case PointField::UINT16:
      return "UINT16";
    case PointField::INT32:
      return "INT32";
    case PointField::UINT32:
      return "UINT32";
    case PointField::FLOAT32:
      return "FLOAT32";
    case PointField::FLOAT64:
      return "FLOAT64";
    default:
      return "unknown";
  }
}

template <typename T>
double readAs(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));  // unaligned-safe
  return static_cast<double>(v);
}

/// Reads one numeric field of any PointField datatype as double.
double readField(const uint8_t* p, uint8_t datatype) {
  switch (datatype) {
    case PointField::INT8:
      return readAs<int8_t>(p);
    case PointField::UINT8:
      return readAs<uint8_t>(p);
    case PointField::INT16:
      return readAs<int16_t>(p);
    case PointField::UINT16:
      return readAs<uint16_t>(p);
    case PointField::INT32:
      return readAs<int32_t>(p);
    case PointField::UINT32:
      return readAs<uint32_t>(p);
    case PointField::FLOAT32:
      return readAs<float>(p);
    case PointField::FLOAT64:
      return readAs<double>(p);
    default:
      return std::numeric_limits<double>::quiet_NaN();
  }
}

struct FieldRef {
  bool present = false;
  uint32_t offset = 0;
  uint8_t datatype = 0;
};

FieldRef findField(const sensor_msgs::PointCloud2& msg, const std::string& name) {
  FieldRef ref;
  for (const auto& f : msg.fields) {
    if (f.name == name) {
      ref.present = true;
      ref.offset = f.offset;
      ref.datatype = f.datatype;
      break;
    }
  }
  return ref;
}

/// The per-point time fields read, in the order of preference (pointTimeFieldName).
bool isTimeField(const std::string& name) {
  return name == "time" || name == "t" || name == "offset_time" || name == "timestamp" ||
         name == "time_sec" || name == "time_nsec";
}

/// Where a cloud keeps its per-point time, and how to read it.
struct TimeLayout {
  PointTimeField field = PointTimeField::kNone;
  FieldRef value;        ///< time, t, offset_time, timestamp or time_sec
  FieldRef nanoseconds;  ///< time_nsec (with time_sec)
};

TimeLayout findTimeLayout(const sensor_msgs::PointCloud2& msg) {
  TimeLayout layout;
  const std::pair<const char*, PointTimeField> relative[] = {
      {"time", PointTimeField::kTime},
      {"t", PointTimeField::kT},
      {"offset_time", PointTimeField::kOffsetTime},
      {"timestamp", PointTimeField::kTimestamp}};
  for (const auto& [name, field] : relative) {
    layout.value = findField(msg, name);
    if (layout.value.present) {
      layout.field = field;
      return layout;
    }
  }
  layout.value = findField(msg, "time_sec");
  layout.nanoseconds = findField(msg, "time_nsec");
  layout.field = layout.value.present && layout.nanoseconds.present ? PointTimeField::kTimeSecNsec
                                                                    : PointTimeField::kNone;
  return layout;
}

/// The point's time [s] relative to the cloud's stamp (NaN when the field holds NaN).
double pointTime(const uint8_t* p, const TimeLayout& layout, const ros::Time& stamp) {
  const double value = readField(p + layout.value.offset, layout.value.datatype);
  switch (layout.field) {
    case PointTimeField::kTime:
      return value;
    case PointTimeField::kT:
    case PointTimeField::kOffsetTime:
      return value * 1e-9;
    case PointTimeField::kTimestamp:
      return value - stamp.toSec();
    case PointTimeField::kTimeSecNsec: {
      // Seconds and nanoseconds apart: a double holding 1.6e9 s keeps only ~0.2 us.
      const double nsec = readField(p + layout.nanoseconds.offset, layout.nanoseconds.datatype);
      return (value - static_cast<double>(stamp.sec)) +
             (nsec - static_cast<double>(stamp.nsec)) * 1e-9;
    }
    case PointTimeField::kNone:
      break;
  }
  return 0.0;
}

}  // namespace

std::string checkCloudFieldTypes(const sensor_msgs::PointCloud2& msg) {
  std::ostringstream problem;
  for (const auto& f : msg.fields) {
    const bool coordinate = f.name == "x" || f.name == "y" || f.name == "z";
    const bool read =
        coordinate || f.name == "intensity" || f.name == "ring" || isTimeField(f.name);
    if (!read) continue;
    if (datatypeSize(f.datatype) == 0) {
      problem << "field '" << f.name << "' has unknown datatype " << static_cast<int>(f.datatype);
      return problem.str();
    }
    // A coordinate stored as an integer is not metres (a UINT8 'x' put 95,129 points in front of
    // the camera instead of 55,058): refused, as is a field holding other than one value.
    if (coordinate && f.datatype != PointField::FLOAT32 && f.datatype != PointField::FLOAT64) {
      problem << "field '" << f.name << "' is " << datatypeName(f.datatype) << " (datatype "
              << static_cast<int>(f.datatype) << "): coordinates must be FLOAT32 or FLOAT64 [m]";
      return problem.str();
    }
    if (f.count != 1) {
      problem << "field '" << f.name << "' has count " << f.count << " ("
              << datatypeName(f.datatype) << "): one value per point is read";
      return problem.str();
    }
  }
  return {};
}

std::string checkCloudLayout(const sensor_msgs::PointCloud2& msg) {
  std::ostringstream problem;
  if (msg.is_bigendian != hostIsBigEndian()) {
    problem << "byte order of the cloud differs from the host's (is_bigendian = "
            << static_cast<int>(msg.is_bigendian) << ")";
    return problem.str();
  }
  for (const char* name : {"x", "y", "z"}) {
    if (!findField(msg, name).present) {
      problem << "no '" << name << "' field (fields:";
      for (const auto& f : msg.fields) problem << " " << f.name;
      problem << ")";
      return problem.str();
    }
  }
  const std::string types = checkCloudFieldTypes(msg);
  if (!types.empty()) return types;
  for (const auto& f : msg.fields) {
    const int size = datatypeSize(f.datatype);
    if (size == 0) continue;  // a field this reader does not read (checkCloudFieldTypes)
    // 64-bit sum: an offset near 2^32 must not wrap round and pass.
    if (static_cast<uint64_t>(f.offset) + static_cast<uint64_t>(size) > msg.point_step) {
      problem << "field '" << f.name << "' (offset " << f.offset << ", " << size
              << " bytes) does not fit in point_step " << msg.point_step;
      return problem.str();
    }
  }
  const size_t points = static_cast<size_t>(msg.width) * msg.height;
  if (points > 0 && static_cast<size_t>(msg.point_step) * msg.width > msg.row_step) {
    problem << "row_step " << msg.row_step << " < point_step * width";
    return problem.str();
  }
  if (points > 0 && msg.data.size() < static_cast<size_t>(msg.row_step) * msg.height) {
    problem << "data has " << msg.data.size() << " bytes, row_step * height needs "
            << static_cast<size_t>(msg.row_step) * msg.height;
    return problem.str();
  }
  return {};
}

const char* pointTimeFieldName(PointTimeField field) {
  switch (field) {
    case PointTimeField::kTime:
      return "time";
    case PointTimeField::kT:
      return "t";
    case PointTimeField::kOffsetTime:
      return "offset_time";
    case PointTimeField::kTimestamp:
      return "timestamp";
    case PointTimeField::kTimeSecNsec:
      return "time_sec + time_nsec";
    case PointTimeField::kNone:
      break;
  }
  return "none";
}

CloudConversion cloudFromMsg(const sensor_msgs::PointCloud2& msg, double max_point_time) {
  const std::string problem = checkCloudLayout(msg);
  if (!problem.empty()) throw ConversionError(problem);
  const FieldRef fx = findField(msg, "x"), fy = findField(msg, "y"), fz = findField(msg, "z");
  const FieldRef fi = findField(msg, "intensity"), fr = findField(msg, "ring");
  const TimeLayout ft = findTimeLayout(msg);
  CloudConversion out;
  out.has_ring = fr.present;
  out.time_field = ft.field;
  out.has_time = ft.field != PointTimeField::kNone;
  const uint64_t total = static_cast<uint64_t>(msg.width) * msg.height;
  if (total > static_cast<uint64_t>(std::numeric_limits<int>::max())) {
    throw ConversionError("cloud of " + std::to_string(total) + " points is too large");
  }
  out.total_points = static_cast<int>(total);
  if (total == 0) return out;  // data may be empty: no pointer arithmetic on it
  out.cloud.reserve(out.total_points);
  for (uint32_t row = 0; row < msg.height; ++row) {
    const uint8_t* row_ptr = msg.data.data() + static_cast<size_t>(row) * msg.row_step;
    for (uint32_t col = 0; col < msg.width; ++col) {
      const uint8_t* p = row_ptr + static_cast<size_t>(col) * msg.point_step;
      LidarPoint point;
      point.x = static_cast<float>(readField(p + fx.offset, fx.datatype));
      point.y = static_cast<float>(readField(p + fy.offset, fy.datatype));
      point.z = static_cast<float>(readField(p + fz.offset, fz.datatype));
      if (!std::isfinite(point.x) || !std::isfinite(point.y) || !std::isfinite(point.z)) {
        ++out.non_finite;
        continue;
      }
      if (std::abs(point.x) > kMaxCoordinate || std::abs(point.y) > kMaxCoordinate ||
          std::abs(point.z) > kMaxCoordinate) {
        ++out.implausible;
        continue;
      }
      if (fi.present) point.intensity = static_cast<float>(readField(p + fi.offset, fi.datatype));
      if (fr.present) {
        const double ring = readField(p + fr.offset, fr.datatype);
        point.ring =
            std::isfinite(ring) && ring >= 0.0 && ring < 65536.0 ? static_cast<int>(ring) : -1;
      }
      if (out.has_time) {
        const double t = pointTime(p, ft, msg.header.stamp);
        if (std::isfinite(t) && std::abs(t) <= max_point_time) {
          point.time = static_cast<float>(t);
        } else {  // named by the caller; the point keeps the stamp's time
          if (out.bad_times++ == 0) out.bad_time_example = t;
        }
      }
      out.cloud.push_back(point);
    }
  }
  return out;
}

sensor_msgs::PointCloud2 cloudToMsg(const LidarCloud& cloud, const std_msgs::Header& header) {
  sensor_msgs::PointCloud2 msg;
  msg.header = header;
  sensor_msgs::PointCloud2Modifier modifier(msg);
  modifier.setPointCloud2Fields(6, "x", 1, PointField::FLOAT32, "y", 1, PointField::FLOAT32, "z", 1,
                                PointField::FLOAT32, "intensity", 1, PointField::FLOAT32, "ring", 1,
                                PointField::UINT16, "time", 1, PointField::FLOAT32);
  modifier.resize(cloud.size());
  sensor_msgs::PointCloud2Iterator<float> x(msg, "x"), y(msg, "y"), z(msg, "z"),
      intensity(msg, "intensity"), time(msg, "time");
  sensor_msgs::PointCloud2Iterator<uint16_t> ring(msg, "ring");
  for (const auto& p : cloud) {
    *x = p.x;
    *y = p.y;
    *z = p.z;
    *intensity = p.intensity;
    *ring = static_cast<uint16_t>(std::max(p.ring, 0));
    *time = p.time;
    ++x, ++y, ++z, ++intensity, ++ring, ++time;
  }
  msg.is_dense = false;
  return msg;
}

}  // namespace conversions
}  // namespace lidar_stereo_fusion
