// libFuzzer target: the YAML parameter loader (io/params_yaml.h), which validates what it loads.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "fuzz_file.h"
#include "lidar_stereo_fusion/io/params_yaml.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  lidar_stereo_fusion::FusionParams params;
  try {
    lidar_stereo_fusion::loadParamsYaml(lsf_fuzz::writeFile("params.yaml", data, size), params);
  } catch (const std::exception&) {  // a rejection; crashes and sanitizer reports are findings
  }
  return 0;
}
