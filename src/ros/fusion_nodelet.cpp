// lidar_stereo_fusion/FusionNodelet: a thin wrapper; all the work is in FusionWorker. It also names
// the remaps that name nothing of the node (ROS ignores them silently: a typo would leave an input
// on its default topic).
#include <memory>
#include <string>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "lidar_stereo_fusion/ros/fusion_worker.h"
#include "lidar_stereo_fusion/ros/node_support.h"

namespace lidar_stereo_fusion {

class FusionNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    const std::map<std::string, std::string> remaps(getRemappingArgs().begin(),
                                                    getRemappingArgs().end());
    for (const std::string& problem : unknownRemaps(remaps, getNodeHandle().getNamespace(),
                                                    getPrivateNodeHandle().getNamespace())) {
      ROS_WARN_STREAM("[" << getName() << "] " << problem);
    }
    worker_ = std::make_unique<FusionWorker>(getNodeHandle(), getPrivateNodeHandle(), getName());
  }
  std::unique_ptr<FusionWorker> worker_;
};

}  // namespace lidar_stereo_fusion

PLUGINLIB_EXPORT_CLASS(lidar_stereo_fusion::FusionNodelet, nodelet::Nodelet)
