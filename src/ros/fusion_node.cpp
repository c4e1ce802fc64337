// fusion_node: runs lidar_stereo_fusion/FusionNodelet in its own process (nodelet::Loader), with
// the node's name, namespace, remappings and private parameters.
#include <nodelet/loader.h>
#include <ros/ros.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "fusion_node");
  nodelet::Loader loader(false);  // no manager services: this process hosts one nodelet
  const nodelet::M_string remappings(ros::names::getRemappings());
  const nodelet::V_string nodelet_argv(argv + 1, argv + argc);
  if (!loader.load(ros::this_node::getName(), "lidar_stereo_fusion/FusionNodelet", remappings,
                   nodelet_argv)) {
    ROS_FATAL(
        "fusion_node: could not load lidar_stereo_fusion/FusionNodelet "
        "(is the package's devel/setup.bash sourced?)");
    return 1;
  }
  ros::spin();
  return 0;
}
