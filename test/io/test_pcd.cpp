// PCD reader/writer: hand-written ascii and binary files with known contents, round trips, and
// malformed files that must throw with a message naming the problem.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "lidar_stereo_fusion/io/pcd.h"

namespace lidar_stereo_fusion {
namespace {

using pcd::readPcd;
using pcd::writePcd;

std::string tempPath(const std::string& name) { return ::testing::TempDir() + "lsf_pcd_" + name; }

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

template <typename T>
void put(std::string& bytes, T value) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  bytes.append(raw, sizeof(T));
}

/// Expects readPcd(path) to throw std::runtime_error whose message contains `needle`.
void expectReadError(const std::string& path, const std::string& needle) {
  try {
    readPcd(path);
    ADD_FAILURE() << "no exception for " << path;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(Pcd, ReadsAsciiWithRingAndSkipsOtherFields) {
  const std::string path = tempPath("ascii.pcd");
  writeText(path,
            "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb intensity ring normal\n"
            "SIZE 4 4 4 4 4 2 4\nTYPE F F F U F U F\nCOUNT 1 1 1 1 1 1 3\n"
            "WIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n"
            "1.5 -2.25 3 4278190080 17 5 0 0 1\n"
            "nan 0 0.125 0 2.5 127 1 0 0\n");
  pcd::Header header;
  const LidarCloud cloud = pcd::readPcd(path, &header);
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(header.data, "ascii");
  EXPECT_TRUE(header.hasField("ring"));
  EXPECT_EQ(cloud[0].x, 1.5f);
  EXPECT_EQ(cloud[0].y, -2.25f);
  EXPECT_EQ(cloud[0].z, 3.0f);
  EXPECT_EQ(cloud[0].intensity, 17.0f);
  EXPECT_EQ(cloud[0].ring, 5);
  EXPECT_TRUE(std::isnan(cloud[1].x));
  EXPECT_EQ(cloud[1].z, 0.125f);
  EXPECT_EQ(cloud[1].ring, 127);
}

TEST(Pcd, ReadsBinaryWithMixedTypesOrganised) {
  // x y z as F4, an F8 field, a U1 intensity, an I2 ring; 2 x 2 organised cloud.
  std::string bytes =
      "VERSION .7\nFIELDS x y z t intensity ring\nSIZE 4 4 4 8 1 2\nTYPE F F F F U I\n"
      "WIDTH 2\nHEIGHT 2\nPOINTS 4\nDATA binary\n";
  for (int i = 0; i < 4; ++i) {
    put<float>(bytes, 0.5f * i);
    put<float>(bytes, -1.0f * i);
    put<float>(bytes, 2.0f + i);
    put<double>(bytes, 123.456);
    put<uint8_t>(bytes, static_cast<uint8_t>(200 + i));
    put<int16_t>(bytes, static_cast<int16_t>(i == 3 ? -1 : 10 * i));
  }
  const std::string path = tempPath("binary.pcd");
  writeText(path, bytes);
  const LidarCloud cloud = readPcd(path);
  ASSERT_EQ(cloud.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(cloud[i].x, 0.5f * i);
    EXPECT_EQ(cloud[i].y, -1.0f * i);
    EXPECT_EQ(cloud[i].z, 2.0f + i);
    EXPECT_EQ(cloud[i].intensity, 200.0f + i);
    EXPECT_EQ(cloud[i].ring, i == 3 ? -1 : 10 * i);
  }
}

TEST(Pcd, RoundTripsBinaryAndAscii) {
  LidarCloud cloud;
  for (int i = 0; i < 50; ++i) {
    LidarPoint p;
    p.x = 0.1f * i;
    p.y = -3.7f + i;
    p.z = 1e-3f * i * i;
    p.intensity = static_cast<float>(i % 7);
    p.ring = i % 16;
    p.time = 1e-4f * i;
    cloud.push_back(p);
  }
  cloud[3].y = std::numeric_limits<float>::quiet_NaN();
  for (bool binary : {true, false}) {
    SCOPED_TRACE(binary ? "binary" : "ascii");
    const std::string path = tempPath(binary ? "rt_bin.pcd" : "rt_ascii.pcd");
    writePcd(path, cloud, binary);
    const LidarCloud back = readPcd(path);
    ASSERT_EQ(back.size(), cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      if (i == 3) {
        EXPECT_TRUE(std::isnan(back[i].y));
      } else {
        EXPECT_EQ(back[i].y, cloud[i].y);
      }
      EXPECT_EQ(back[i].x, cloud[i].x);
      EXPECT_EQ(back[i].z, cloud[i].z);
      EXPECT_EQ(back[i].intensity, cloud[i].intensity);
      EXPECT_EQ(back[i].ring, cloud[i].ring);
      EXPECT_EQ(back[i].time, cloud[i].time);
    }
  }
  // Without rings on every point, no ring field is written: rings read back as -1.
  cloud[0].ring = -1;
  writePcd(tempPath("noring.pcd"), cloud);
  pcd::Header header;
  const LidarCloud back = readPcd(tempPath("noring.pcd"), &header);
  EXPECT_FALSE(header.hasField("ring"));
  EXPECT_EQ(back[5].ring, -1);
}

TEST(Pcd, MalformedFilesThrowNamingTheProblem) {
  expectReadError(tempPath("does_not_exist.pcd"), "cannot open");
  const std::string head = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";
  writeText(tempPath("noz.pcd"),
            "FIELDS x y i\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n");
  expectReadError(tempPath("noz.pcd"), "x, y and z");
  writeText(tempPath("trunc.pcd"), head + "WIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA binary\n12345678");
  expectReadError(tempPath("trunc.pcd"), "truncated");
  writeText(tempPath("huge.pcd"),
            head + "WIDTH 2000000000\nHEIGHT 1000\nPOINTS 2000000000000\nDATA binary\n1234");
  expectReadError(tempPath("huge.pcd"), "truncated");
  writeText(tempPath("overflow.pcd"), head + "WIDTH 99999999999999999999\nDATA ascii\n");
  expectReadError(tempPath("overflow.pcd"), "WIDTH");
  writeText(tempPath("lzf.pcd"), head + "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA binary_compressed\n");
  expectReadError(tempPath("lzf.pcd"), "binary_compressed");
  writeText(tempPath("points.pcd"), head + "WIDTH 2\nHEIGHT 1\nPOINTS 3\nDATA ascii\n");
  expectReadError(tempPath("points.pcd"), "POINTS");
  writeText(tempPath("tokens.pcd"), head + "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2\n");
  expectReadError(tempPath("tokens.pcd"), "has 2 values");
  writeText(tempPath("word.pcd"), head + "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 x\n");
  expectReadError(tempPath("word.pcd"), "non-number");
  writeText(tempPath("size.pcd"),
            "FIELDS x y z\nSIZE 4 4 3\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n");
  expectReadError(tempPath("size.pcd"), "SIZE 3");
  writeText(tempPath("lengths.pcd"),
            "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n");
  expectReadError(tempPath("lengths.pcd"), "different lengths");
  writeText(tempPath("nodata.pcd"), head + "WIDTH 1\n");
  expectReadError(tempPath("nodata.pcd"), "no DATA");
}

}  // namespace
}  // namespace lidar_stereo_fusion
