// libFuzzer target: KITTI Velodyne .bin reader, then ring recovery and projection of the sweep.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "fuzz_file.h"
#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/io/kitti.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  namespace lsf = lidar_stereo_fusion;
  lsf::LidarCloud cloud;
  try {
    cloud = lsf::kitti::readVelodyneBin(lsf_fuzz::writeFile("sweep.bin", data, size));
  } catch (const std::exception&) {  // a rejection; crashes and sanitizer reports are findings
    return 0;
  }
  lsf::ensureRings(cloud, false, 64);
  lsf::StereoCamera camera;
  camera.fx = camera.fy = 60;
  camera.cx = 40;
  camera.cy = 30;
  camera.baseline = 0.5;
  camera.width = 80;
  camera.height = 60;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  lsf::projectCloud(cloud, T, camera, lsf::ProjectionParams());
  return 0;
}
