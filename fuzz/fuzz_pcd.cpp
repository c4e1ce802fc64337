// libFuzzer target: the PCD reader (this package's checks, then PCL's reader: ascii, binary,
// binary_compressed; io/pcd.h). PCL's own error prints are silenced (they only slow the run).
#include <cstddef>
#include <cstdint>
#include <exception>

#include <pcl/console/print.h>

#include "fuzz_file.h"
#include "lidar_stereo_fusion/io/pcd.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  try {
    lidar_stereo_fusion::pcd::readPcd(lsf_fuzz::writeFile("cloud.pcd", data, size));
  } catch (const std::exception&) {  // a rejection; crashes and sanitizer reports are findings
  }
  return 0;
}
