// libFuzzer target: Autoware calibration reader (OpenCV FileStorage YAML).
#include <cstddef>
#include <cstdint>
#include <exception>

#include "fuzz_file.h"
#include "lidar_stereo_fusion/io/calibration_autoware.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  namespace lsf = lidar_stereo_fusion;
  try {
    const auto calib =
        lsf::readAutowareCalibration(lsf_fuzz::writeFile("autoware.yaml", data, size));
    lsf::cameraFromLidar(calib);
    lsf::meanReprojectionError(calib);
  } catch (const std::exception&) {  // a rejection; crashes and sanitizer reports are findings
  }
  return 0;
}
