# Targets of the ROS layer: the fusion nodelet (library + plugin XML) and the fusion_node
# executable, plus the install rules of launch, config and rviz files. Included after the core
# targets, with catkin set up by cmake/ros_catkin.cmake.
#
#   lidar_stereo_fusion_ros   conversions, parameters, the frame path, the worker and the nodelet
#                             plugin
#   fusion_node               loads lidar_stereo_fusion/FusionNodelet with nodelet::Loader

set(LSF_ROS_INCLUDE_DIRS
  ${catkin_INCLUDE_DIRS}
  ${CATKIN_DEVEL_PREFIX}/${CATKIN_GLOBAL_INCLUDE_DESTINATION})  # FusionConfig.h, FusionStats.h

add_library(${PROJECT_NAME}_ros
  src/ros/conversions.cpp
  src/ros/cloud_conversions.cpp
  src/ros/ego_motion.cpp
  src/ros/ros_params.cpp
  src/ros/node_support.cpp
  src/ros/stereo_sync.cpp
  src/ros/input_gate.cpp
  src/ros/image_input.cpp
  src/ros/stereo_order.cpp
  src/ros/input_watch.cpp
  src/ros/frame_input.cpp
  src/ros/output_publisher.cpp
  src/ros/rate_governor.cpp
  src/ros/fusion_worker.cpp
  src/ros/fusion_nodelet.cpp)
target_include_directories(${PROJECT_NAME}_ros PUBLIC
  $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>)
target_include_directories(${PROJECT_NAME}_ros SYSTEM PUBLIC ${LSF_ROS_INCLUDE_DIRS})
target_link_libraries(${PROJECT_NAME}_ros PUBLIC ${PROJECT_NAME}_node_params ${catkin_LIBRARIES})
# Generated headers (dynamic_reconfigure config, FusionStats message) come first.
add_dependencies(${PROJECT_NAME}_ros ${PROJECT_NAME}_gencfg ${PROJECT_NAME}_generate_messages_cpp)
if(catkin_EXPORTED_TARGETS)
  add_dependencies(${PROJECT_NAME}_ros ${catkin_EXPORTED_TARGETS})
endif()

add_executable(fusion_node src/ros/fusion_node.cpp)
target_include_directories(fusion_node SYSTEM PRIVATE ${LSF_ROS_INCLUDE_DIRS})
target_link_libraries(fusion_node ${catkin_LIBRARIES})
# The node loads the plugin at run time; build it alongside so that `fusion_node` always works.
add_dependencies(fusion_node ${PROJECT_NAME}_ros)

install(TARGETS ${PROJECT_NAME}_ros fusion_node
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
install(FILES nodelet_plugins.xml pcl_ros_plugins.xml DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})
install(FILES launch/fusion.launch launch/zed_vls128.launch launch/playback.launch
  DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION}/launch)
install(DIRECTORY config rviz DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})
