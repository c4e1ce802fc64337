// libFuzzer target: PointCloud2 checks and conversion (src/ros/conversions.cpp), then ring
// recovery on what comes out. Any exception other than ConversionError is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_messages.h"
#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/ros/conversions.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  namespace conv = lidar_stereo_fusion::conversions;
  const sensor_msgs::PointCloud2 msg = lsf_fuzz::decodeCloud(data, size);
  conv::checkCloudLayout(msg);
  try {
    conv::CloudConversion cloud = conv::cloudFromMsg(msg);
    if (!cloud.cloud.empty()) lidar_stereo_fusion::ensureRings(cloud.cloud, cloud.has_ring, 64);
  } catch (const conv::ConversionError&) {
  }
  return 0;
}
