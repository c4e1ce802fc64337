// libFuzzer target: Image checks and conversion (src/ros/conversions.cpp). Any exception other
// than ConversionError (e.g. an escaping cv::Exception) is a finding.
#include <cstddef>
#include <cstdint>

#include <boost/make_shared.hpp>

#include "fuzz_messages.h"
#include "lidar_stereo_fusion/ros/conversions.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  namespace conv = lidar_stereo_fusion::conversions;
  const auto msg = boost::make_shared<sensor_msgs::Image>(lsf_fuzz::decodeImage(data, size));
  conv::checkImage(*msg);
  try {
    conv::imageToCore(msg);
  } catch (const conv::ConversionError&) {
  }
  return 0;
}
