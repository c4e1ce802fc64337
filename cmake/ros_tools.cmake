# Targets of the ROS tools (calibration publishers, bag converter). Included after the core
# targets and cmake/ros_targets.cmake, with catkin already set up (cmake/ros_catkin.cmake).
# Their sources are in tools/ros/ (as tools/ holds the ROS-free tools): tools/ros/<tool>.cpp, a
# tool's own further sources in tools/ros/<tool>/, and the messages shared by several in
# tools/ros/calibration_msgs/.
#
#   autoware_calibration_publisher  static TF lidar -> camera (+ camera_info) from Autoware YAML
#   kitti_calibration_publisher     static TF velodyne -> left -> right camera from KITTI calib
#   kitti_to_bag                    KITTI raw drive -> ROS 1 bag with the rig's topics
#   bag_runner                      the fusion on every image set of recorded bags (no roscore)
#   lsf_batch                       bag_runner over archives of bags on Dask distributed (Python)
# (lsf_params, which writes or checks the files generated from the parameter tables, is a ROS-free
# tool: tools/lsf_params.cpp.)

# ROS messages built from the ROS-free calibration readers (and the KITTI oxts ego-motion as TF);
# shared by the tools and their tests.
add_library(${PROJECT_NAME}_calibration_msgs STATIC
  tools/ros/calibration_msgs/calibration_msgs.cpp tools/ros/calibration_msgs/kitti_ego_motion.cpp)
target_include_directories(${PROJECT_NAME}_calibration_msgs SYSTEM PUBLIC ${catkin_INCLUDE_DIRS})
target_link_libraries(${PROJECT_NAME}_calibration_msgs PUBLIC
  ${PROJECT_NAME}_io ${catkin_LIBRARIES})
set_target_properties(${PROJECT_NAME}_calibration_msgs PROPERTIES POSITION_INDEPENDENT_CODE ON)
if(catkin_EXPORTED_TARGETS)
  add_dependencies(${PROJECT_NAME}_calibration_msgs ${catkin_EXPORTED_TARGETS})
endif()

add_executable(autoware_calibration_publisher tools/ros/autoware_calibration_publisher.cpp)
add_executable(kitti_calibration_publisher tools/ros/kitti_calibration_publisher.cpp)
add_executable(kitti_to_bag tools/ros/kitti_to_bag.cpp tools/ros/kitti_to_bag/kitti_bag_frames.cpp)
set(LSF_ROS_TOOLS autoware_calibration_publisher kitti_calibration_publisher kitti_to_bag)
foreach(tool ${LSF_ROS_TOOLS})
  target_link_libraries(${tool} ${PROJECT_NAME}_calibration_msgs)
endforeach()
# The sweep message: conversions::cloudToMsg, the fields of velodyne_pointcloud.
target_link_libraries(kitti_to_bag ${PROJECT_NAME}_ros)

# bag_runner: the node's pairing (stereo_sync.h) fed from bags; its parts (tools/ros/bag_runner/)
# in a library for tests, which include them as "bag_runner/bag_<part>.h".
add_library(${PROJECT_NAME}_bag STATIC tools/ros/bag_runner/bag_pairing.cpp
  tools/ros/bag_runner/bag_outputs.cpp tools/ros/bag_runner/bag_inputs.cpp
  tools/ros/bag_runner/bag_files.cpp tools/ros/bag_runner/bag_manifest.cpp
  tools/ros/bag_runner/bag_run.cpp)
target_include_directories(${PROJECT_NAME}_bag PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/tools/ros)
target_link_libraries(${PROJECT_NAME}_bag PUBLIC ${PROJECT_NAME}_ros)
# The manifest of an output folder names the package version (package.xml, read by catkin).
target_compile_definitions(${PROJECT_NAME}_bag PRIVATE
  LSF_PACKAGE_VERSION="${${PROJECT_NAME}_VERSION}")
add_executable(bag_runner tools/ros/bag_runner.cpp)
target_link_libraries(bag_runner ${PROJECT_NAME}_bag)
list(APPEND LSF_ROS_TOOLS bag_runner)
catkin_install_python(PROGRAMS scripts/lsf_batch DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
install(FILES scripts/lsf_batch_plan.py DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

install(TARGETS ${LSF_ROS_TOOLS} RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
install(FILES launch/calibration_autoware.launch launch/calibration_kitti.launch
  DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION}/launch)
