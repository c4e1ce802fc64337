// libFuzzer target: KITTI calibration reader. The first byte chooses which of the two files gets
// the rest of the input; the other is a valid one. Exceptions are rejections.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <fstream>

#include "fuzz_file.h"
#include "lidar_stereo_fusion/io/kitti.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const bool velo = data[0] & 1;
  lsf_fuzz::writeFile(velo ? "calib_velo_to_cam.txt" : "calib_cam_to_cam.txt", data + 1, size - 1);
  std::ofstream(lsf_fuzz::scratch() / (velo ? "calib_cam_to_cam.txt" : "calib_velo_to_cam.txt"))
      << (velo ? "R_rect_00: 1 0 0 0 1 0 0 0 1\nP_rect_02: 60 0 40 3 0 60 30 0 0 0 1 0\n"
                 "P_rect_03: 60 0 40 -27 0 60 30 0 0 0 1 0\nS_rect_02: 80 60\n"
               : "R: 0 -1 0 0 0 -1 1 0 0\nT: 0 0 0\n");
  try {
    lidar_stereo_fusion::kitti::readCalibration(lsf_fuzz::scratch().string());
  } catch (const std::exception&) {  // a rejection; crashes and sanitizer reports are findings
  }
  return 0;
}
