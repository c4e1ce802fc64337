// libFuzzer target: the PCD reader (ascii, binary; io/pcd.h).
#include <cstddef>
#include <cstdint>
#include <exception>

#include "fuzz_file.h"
#include "lidar_stereo_fusion/io/pcd.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  try {
    lidar_stereo_fusion::pcd::readPcd(lsf_fuzz::writeFile("cloud.pcd", data, size));
  } catch (const std::exception&) {  // a rejection; crashes and sanitizer reports are findings
  }
  return 0;
}
