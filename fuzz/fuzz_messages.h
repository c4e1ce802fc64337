// The byte layouts the PointCloud2 and Image fuzz targets decode into ROS messages, and the
// encoders the tests use to write the seed corpora (test/ros/test_input_attacks.cpp). Decoding
// never allocates more than the input holds, unlike ROS deserialisation of arbitrary bytes
// (which resizes vectors to any length it reads), so the fuzzer explores our checks, not that.
//
// PointCloud2: u32 width, u32 height, u32 point_step, u32 row_step, u8 is_bigendian, u8 fields
//              (mod 9), per field {u8 name index, u32 offset, u8 datatype, u32 count}, data = rest.
// Image:       u32 width, u32 height, u32 step, u8 encoding index, u8 is_bigendian, data = rest.
// Integers little-endian; a short input gives zeros.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>

namespace lsf_fuzz {

inline const std::vector<std::string>& fieldNames() {
  // The per-point time fields of the common drivers (conversions::PointTimeField) included;
  // "other" stays last (encodeCloud writes it for any name not listed).
  static const std::vector<std::string> kNames = {
      "x",           "y",         "z",        "intensity", "ring", "time", "t",
      "offset_time", "timestamp", "time_sec", "time_nsec", "rgb",  "other"};
  return kNames;
}
inline const std::vector<std::string>& encodings() {
  static const std::vector<std::string> kEncodings = {
      "bgra8", "rgba8", "bgr8", "rgb8", "mono8", "16UC1", "32FC1", "bayer_rggb8", ""};
  return kEncodings;
}

class ByteReader {
 public:
  ByteReader(const uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  template <class T>
  T take() {
    T value = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) {
      const T byte = pos_ < size_ ? data_[pos_] : 0;
      value = static_cast<T>(value | static_cast<T>(byte << (8 * i)));
      ++pos_;
    }
    return value;
  }
  std::vector<uint8_t> rest() const {
    return pos_ < size_ ? std::vector<uint8_t>(data_ + pos_, data_ + size_)
                        : std::vector<uint8_t>();
  }

 private:
  const uint8_t* data_;
  std::size_t size_, pos_ = 0;
};

class ByteWriter {
 public:
  template <class T>
  void put(T value) {
    for (std::size_t i = 0; i < sizeof(T); ++i)
      bytes.push_back(static_cast<uint8_t>(value >> (8 * i)));
  }
  std::vector<uint8_t> bytes;
};

inline sensor_msgs::PointCloud2 decodeCloud(const uint8_t* data, std::size_t size) {
  ByteReader in(data, size);
  sensor_msgs::PointCloud2 msg;
  msg.header.frame_id = "velodyne";
  msg.width = in.take<uint32_t>();
  msg.height = in.take<uint32_t>();
  msg.point_step = in.take<uint32_t>();
  msg.row_step = in.take<uint32_t>();
  msg.is_bigendian = in.take<uint8_t>() & 1;
  const int fields = in.take<uint8_t>() % 9;
  for (int i = 0; i < fields; ++i) {
    sensor_msgs::PointField f;
    f.name = fieldNames()[in.take<uint8_t>() % fieldNames().size()];
    f.offset = in.take<uint32_t>();
    f.datatype = in.take<uint8_t>();
    f.count = in.take<uint32_t>();
    msg.fields.push_back(f);
  }
  msg.data = in.rest();
  return msg;
}

inline std::vector<uint8_t> encodeCloud(const sensor_msgs::PointCloud2& msg) {
  ByteWriter out;
  out.put<uint32_t>(msg.width);
  out.put<uint32_t>(msg.height);
  out.put<uint32_t>(msg.point_step);
  out.put<uint32_t>(msg.row_step);
  out.put<uint8_t>(msg.is_bigendian);
  out.put<uint8_t>(static_cast<uint8_t>(msg.fields.size()));
  for (const auto& f : msg.fields) {
    uint8_t name = static_cast<uint8_t>(fieldNames().size() - 1);
    for (std::size_t k = 0; k < fieldNames().size(); ++k) {
      if (fieldNames()[k] == f.name) name = static_cast<uint8_t>(k);
    }
    out.put<uint8_t>(name);
    out.put<uint32_t>(f.offset);
    out.put<uint8_t>(f.datatype);
    out.put<uint32_t>(f.count);
  }
  out.bytes.insert(out.bytes.end(), msg.data.begin(), msg.data.end());
  return out.bytes;
}

inline sensor_msgs::Image decodeImage(const uint8_t* data, std::size_t size) {
  ByteReader in(data, size);
  sensor_msgs::Image msg;
  msg.header.frame_id = "left";
  msg.width = in.take<uint32_t>();
  msg.height = in.take<uint32_t>();
  msg.step = in.take<uint32_t>();
  msg.encoding = encodings()[in.take<uint8_t>() % encodings().size()];
  msg.is_bigendian = in.take<uint8_t>() & 1;
  msg.data = in.rest();
  return msg;
}

inline std::vector<uint8_t> encodeImage(const sensor_msgs::Image& msg) {
  ByteWriter out;
  out.put<uint32_t>(msg.width);
  out.put<uint32_t>(msg.height);
  out.put<uint32_t>(msg.step);
  uint8_t encoding = static_cast<uint8_t>(encodings().size() - 1);
  for (std::size_t k = 0; k < encodings().size(); ++k) {
    if (encodings()[k] == msg.encoding) encoding = static_cast<uint8_t>(k);
  }
  out.put<uint8_t>(encoding);
  out.put<uint8_t>(msg.is_bigendian);
  out.bytes.insert(out.bytes.end(), msg.data.begin(), msg.data.end());
  return out.bytes;
}

}  // namespace lsf_fuzz
