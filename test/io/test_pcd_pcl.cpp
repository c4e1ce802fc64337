// The PCD reader beside PCL (issue 26): binary_compressed files PCL writes are read exactly,
// corrupt ones are refused with this package's messages, and the cases where PCL's reader alone
// would accept a bad file (the reason the ascii checks stay hand-written).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include "lidar_stereo_fusion/io/pcd.h"

namespace lidar_stereo_fusion {
namespace {

std::string tempPath(const std::string& name) { return ::testing::TempDir() + "lsf_pcl_" + name; }

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

/// The message of readPcd's exception ("" when it did not throw).
std::string readError(const std::string& path) {
  try {
    pcd::readPcd(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

LidarCloud sweep(int n) {
  LidarCloud cloud;
  for (int i = 0; i < n; ++i) {
    LidarPoint p;
    p.x = 0.37f * i;
    p.y = -2.5f + 0.01f * i;
    p.z = std::sin(0.1f * i);
    p.intensity = static_cast<float>(i % 100);
    p.ring = i % 64;
    p.time = 1e-5f * i;
    cloud.push_back(p);
  }
  return cloud;
}

/// Offset of the first byte after "DATA binary_compressed\n".
std::size_t dataStart(const std::string& bytes) {
  const std::string tag = "DATA binary_compressed\n";
  return bytes.find(tag) + tag.size();
}

TEST(PcdPcl, ReadsBinaryCompressedExactly) {
  const LidarCloud cloud = sweep(5000);
  const std::string path = tempPath("compressed.pcd");
  pcd::writePcd(path, cloud, pcd::DataKind::kBinaryCompressed);
  ASSERT_NE(readBytes(path).find("DATA binary_compressed\n"), std::string::npos);
  pcd::Header header;
  const LidarCloud back = pcd::readPcd(path, &header);
  EXPECT_EQ(header.data, "binary_compressed");
  ASSERT_EQ(back.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_EQ(back[i].x, cloud[i].x);
    EXPECT_EQ(back[i].y, cloud[i].y);
    EXPECT_EQ(back[i].z, cloud[i].z);
    EXPECT_EQ(back[i].intensity, cloud[i].intensity);
    EXPECT_EQ(back[i].ring, cloud[i].ring);
    EXPECT_EQ(back[i].time, cloud[i].time);
  }
}

TEST(PcdPcl, CorruptBinaryCompressedIsRefusedWithThisPackagesMessages) {
  const std::string good = tempPath("good.pcd");
  pcd::writePcd(good, sweep(3000), pcd::DataKind::kBinaryCompressed);
  const std::string bytes = readBytes(good);
  const std::size_t at = dataStart(bytes);
  uint32_t sizes[2];
  std::memcpy(sizes, bytes.data() + at, sizeof(sizes));
  ASSERT_EQ(sizes[1], 3000u * 22u);  // x y z intensity ring time: 4 + 4 + 4 + 4 + 2 + 4 bytes
  auto withSizes = [&](uint32_t compressed, uint32_t uncompressed) {
    std::string out = bytes;
    std::memcpy(&out[at], &compressed, 4);
    std::memcpy(&out[at + 4], &uncompressed, 4);
    return out;
  };
  struct Case {
    std::string name, bytes, message;
  };
  std::string flipped = bytes;
  for (std::size_t k = at + 8; k < flipped.size(); k += 97)
    flipped[k] = static_cast<char>(~flipped[k]);
  const Case cases[] = {
      {"no_sizes", bytes.substr(0, at + 3), "no compressed and uncompressed sizes"},
      {"cut", bytes.substr(0, at + 8 + sizes[0] / 2), "compressed bytes announced"},
      {"wrong_uncompressed", withSizes(sizes[0], sizes[1] - 22), "need 66000"},
      {"impossible_ratio", withSizes(16, sizes[1]), "cannot hold"},
      {"flipped_lzf", flipped, "the LZF data is corrupt"},
  };
  for (const Case& c : cases) {
    const std::string path = tempPath(c.name + ".pcd");
    writeBytes(path, c.bytes);
    const std::string error = readError(path);
    EXPECT_NE(error.find(c.message), std::string::npos) << c.name << ": '" << error << "'";
    EXPECT_NE(error.find(path), std::string::npos) << c.name << ": the file is named";
  }
}

// Why checkAscii (src/io/pcd.cpp) stays hand-written: PCL's reader reports success for ascii
// files that hold no number where one should be, or too few values, and fills in 0.
TEST(PcdPcl, PclAloneAcceptsBadAsciiThatThisReaderRefuses) {
  const std::string head =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\n"
      "POINTS 1\nDATA ascii\n";
  const struct {
    std::string name, line, message;
  } cases[] = {{"word", "1 2 x\n", "non-number 'x'"}, {"short", "1 2\n", "has 2 values"}};
  for (const auto& c : cases) {
    const std::string path = tempPath(c.name + ".pcd");
    writeBytes(path, head + c.line);
    pcl::PCLPointCloud2 cloud;
    EXPECT_GE(pcl::PCDReader().read(path, cloud), 0) << c.name << ": PCL refuses it now; "
                                                     << "checkAscii may go";
    ASSERT_EQ(cloud.data.size(), 12u);
    float z = -1.f;
    std::memcpy(&z, cloud.data.data() + 8, 4);
    EXPECT_EQ(z, 0.f) << c.name << ": PCL's value for the bad or missing z";
    EXPECT_NE(readError(path).find(c.message), std::string::npos) << c.name;
  }
}

// Headers on which PCL 1.13's reader crashed (SIGSEGV; found by fuzz/fuzz_pcd.cpp): PCL stops
// parsing at a line it does not know and reads on without POINTS. Refused here before PCL.
TEST(PcdPcl, HeadersThatCrashedPclAreRefusedFirst) {
  const std::string fields = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";
  const std::string rest = "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA binary\n123456789012";
  const struct {
    std::string name, bytes, message;
  } cases[] = {
      {"nul",
       std::string("VERSIO\xc8\t\0\0"
                   "7\n",
                   11) +
           fields + rest,
       "holds byte 200"},
      {"unknown_key", "VIEWPOI 0.7\n" + fields + rest, "unknown line 'VIEWPOI ...'"},
      {"no_points", fields + "WIDTH 1\nHEIGHT 1\nPODATA 1\nDATA binary\n123456789012",
       "unknown line 'PODATA ...'"},
      {"points_missing", fields + "WIDTH 1\nHEIGHT 1\nDATA binary\n123456789012", "no POINTS"},
      {"blank_line", fields + "   \n" + rest, "holds only blanks"},
      {"viewpoint", fields + "VIEWPOINT 0 0 0\n" + rest, "VIEWPOINT needs 7 numbers"},
  };
  for (const auto& c : cases) {
    const std::string path = tempPath(c.name + ".pcd");
    writeBytes(path, c.bytes);
    const std::string error = readError(path);
    EXPECT_NE(error.find(c.message), std::string::npos) << c.name << ": '" << error << "'";
  }
}

TEST(PcdPcl, UnknownDataKindIsNamed) {
  writeBytes(tempPath("zip.pcd"),
             "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA zip\n");
  // and a header of known lines in an order PCL refuses (COUNT before TYPE), or one repeated
  const std::string order =
      "FIELDS x y z\nSIZE 4 4 4\nCOUNT 1 1 1\nTYPE F F F\nWIDTH 1\n"
      "POINTS 1\nDATA ascii\n1 2 3\n";
  writeBytes(tempPath("order.pcd"), order);
  pcl::PCLPointCloud2 cloud;
  EXPECT_LT(pcl::PCDReader().read(tempPath("order.pcd"), cloud), 0) << "PCL reads it now";
  EXPECT_NE(readError(tempPath("order.pcd")).find("line 4 (TYPE) is out of order"),
            std::string::npos);
  writeBytes(tempPath("twice.pcd"),
             "FIELDS x y z\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n"
             "WIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n");
  EXPECT_NE(readError(tempPath("twice.pcd")).find("line 2 (FIELDS) is out of order or repeated"),
            std::string::npos);
  EXPECT_NE(readError(tempPath("zip.pcd")).find("unknown DATA 'zip'"), std::string::npos);
}

}  // namespace
}  // namespace lidar_stereo_fusion
