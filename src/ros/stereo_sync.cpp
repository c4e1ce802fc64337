#include "lidar_stereo_fusion/ros/stereo_sync.h"

#include "lidar_stereo_fusion/ros/conversions.h"

namespace lidar_stereo_fusion {

namespace {

std::string sizeText(uint32_t width, uint32_t height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

}  // namespace

boost::optional<Rejection> checkImageSet(const ImageSet& set) {
  std::string problem = conversions::checkImage(*set.left);
  if (!problem.empty()) return Rejection{kLeftImage, "image", problem};
  problem = conversions::checkImage(*set.right);
  if (!problem.empty()) return Rejection{kRightImage, "image", problem};
  if (set.left->width != set.right->width || set.left->height != set.right->height) {
    return Rejection{kRightImage, "size",
                     "size " + sizeText(set.right->width, set.right->height) +
                         " differs from the left image's " +
                         sizeText(set.left->width, set.left->height)};
  }
  if (set.left_info->width != set.left->width || set.left_info->height != set.left->height) {
    return Rejection{kLeftInfo, "size",
                     "camera_info is " + sizeText(set.left_info->width, set.left_info->height) +
                         " but the image is " + sizeText(set.left->width, set.left->height)};
  }
  if (set.right_info->width != set.right->width || set.right_info->height != set.right->height) {
    return Rejection{kRightInfo, "size",
                     "camera_info is " + sizeText(set.right_info->width, set.right_info->height) +
                         " but the image is " + sizeText(set.right->width, set.right->height)};
  }
  try {
    conversions::stereoCameraFromInfo(*set.left_info, *set.right_info);
  } catch (const conversions::CameraInfoError& e) {
    return Rejection{e.left ? kLeftInfo : kRightInfo, "calibration", e.what()};
  }
  if (set.left->header.frame_id.empty()) {
    return Rejection{kLeftImage, "frame_id",
                     "empty frame_id (the left optical frame is needed for TF)"};
  }
  return boost::none;
}

boost::optional<Rejection> checkCloud(const sensor_msgs::PointCloud2& cloud) {
  // Field types first, as their own kind of problem: a cloud of the wrong types is not a damaged
  // one, and its warning must not be throttled away by another layout problem's.
  const std::string types = conversions::checkCloudFieldTypes(cloud);
  if (!types.empty()) return Rejection{kCloud, "field type", types};
  const std::string problem = conversions::checkCloudLayout(cloud);
  if (!problem.empty()) return Rejection{kCloud, "layout", problem};
  if (cloud.width == 0 || cloud.height == 0) {
    return Rejection{kCloud, "empty", "empty cloud (0 points)"};
  }
  if (cloud.header.frame_id.empty()) return Rejection{kCloud, "frame_id", "empty frame_id"};
  return boost::none;
}

}  // namespace lidar_stereo_fusion
