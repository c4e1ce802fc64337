// lidar_stereo_fusion/FusionNodelet: a thin wrapper; all the work is in FusionWorker.
#include <memory>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "lidar_stereo_fusion/ros/fusion_worker.h"

namespace lidar_stereo_fusion {

class FusionNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    worker_ = std::make_unique<FusionWorker>(getNodeHandle(), getPrivateNodeHandle(), getName());
  }
  std::unique_ptr<FusionWorker> worker_;
};

}  // namespace lidar_stereo_fusion

PLUGINLIB_EXPORT_CLASS(lidar_stereo_fusion::FusionNodelet, nodelet::Nodelet)
