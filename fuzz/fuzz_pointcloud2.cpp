// libFuzzer target: PointCloud2 checks and conversion (src/ros/cloud_conversions.cpp, per-point
// time fields included), then ring recovery and motion compensation over the points' time span on
// what comes out. Any exception other than ConversionError is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_messages.h"
#include "lidar_stereo_fusion/core/lidar_projection.h"
#include "lidar_stereo_fusion/core/motion_compensation.h"
#include "lidar_stereo_fusion/ros/conversions.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  namespace conv = lidar_stereo_fusion::conversions;
  const sensor_msgs::PointCloud2 msg = lsf_fuzz::decodeCloud(data, size);
  conv::checkCloudLayout(msg);
  try {
    conv::CloudConversion cloud = conv::cloudFromMsg(msg);
    if (!cloud.cloud.empty()) lidar_stereo_fusion::ensureRings(cloud.cloud, cloud.has_ring, 64);
    const auto span = lidar_stereo_fusion::timeSpan(cloud.cloud);
    lidar_stereo_fusion::compensateMotion(
        cloud.cloud, lidar_stereo_fusion::constantVelocityMotion(
                         Eigen::Vector3d(20.0, 0.0, 0.0), Eigen::Vector3d(0.0, 0.0, 0.5), 0.0,
                         lidar_stereo_fusion::sampleTimes(span.first, span.second, 5)));
  } catch (const conv::ConversionError&) {
  }
  return 0;
}
