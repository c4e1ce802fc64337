# catkin setup of the ROS layer. Included from CMakeLists.txt before the core targets.
# Message and dynamic_reconfigure generation must come before catkin_package().
#
# Component names are those of Debian 12's ROS 1 packages (they match the ROS wiki names).
set(LSF_CATKIN_COMPONENTS
  roscpp nodelet pluginlib tf2 tf2_ros tf2_eigen tf2_msgs message_filters cv_bridge
  image_transport sensor_msgs stereo_msgs std_msgs geometry_msgs dynamic_reconfigure
  diagnostic_updater diagnostic_msgs rosbag message_generation)
find_package(catkin REQUIRED COMPONENTS ${LSF_CATKIN_COMPONENTS})
# pcl_conversions (header-only): the tests that compare this package's PointCloud2 checks and the
# pcl_ros filters with PCL's own conversion. The nodelet itself reads clouds without it
# (doc/libraries.md says why).
find_package(pcl_conversions REQUIRED)

add_message_files(DIRECTORY msg FILES FusionStats.msg)
generate_messages(DEPENDENCIES std_msgs)
generate_dynamic_reconfigure_options(cfg/Fusion.cfg)

catkin_package(
  INCLUDE_DIRS include
  LIBRARIES ${PROJECT_NAME}_core ${PROJECT_NAME}_io ${PROJECT_NAME}_sim ${PROJECT_NAME}_eval
            ${PROJECT_NAME}_node_params ${PROJECT_NAME}_ros
  CATKIN_DEPENDS roscpp nodelet tf2_ros message_filters cv_bridge image_transport sensor_msgs
                 stereo_msgs std_msgs message_runtime dynamic_reconfigure diagnostic_updater
  DEPENDS OpenCV)
set(LSF_LIB_DEST ${CATKIN_PACKAGE_LIB_DESTINATION})
set(LSF_BIN_DEST ${CATKIN_PACKAGE_BIN_DESTINATION})
set(LSF_INCLUDE_DEST ${CATKIN_GLOBAL_INCLUDE_DESTINATION})
