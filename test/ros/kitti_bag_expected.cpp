// The core pipeline's depth for one KITTI frame, for test_kitti_bag.
#include "kitti_bag_expected.h"

#include "lidar_stereo_fusion/core/pipeline.h"
#include "lidar_stereo_fusion/io/params_yaml.h"

namespace lidar_stereo_fusion {
namespace test {

cv::Mat1f expectedDepth(const std::string& params_yaml, const kitti::Frame& frame,
                        const kitti::Calibration& calib, const Eigen::Isometry3d& T_cam_lidar) {
  FusionParams params;
  loadParamsYaml(params_yaml, params);
  FusionPipeline pipeline(params);
  const kitti::FrameData files = kitti::loadFrame(frame, calib.camera);
  FusionInput input;
  input.left = files.left;
  input.right = files.right;
  input.cloud = files.cloud;
  input.camera = calib.camera;
  input.T_cam_lidar = T_cam_lidar;
  return pipeline.process(input).depth;
}

}  // namespace test
}  // namespace lidar_stereo_fusion
