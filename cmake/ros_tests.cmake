# Tests of the ROS layer (nodelet, node, launch files, RViz config). Included after the core tests
# when testing is enabled, with catkin set up and the ROS targets defined.
#
#   test_ros_unit            conversions, sweep matching, the frame path, parameter mapping,
#                            launch arguments, what PCL's cloud conversion does not check (no
#                            ROS master)
#   fusion_nodelet.test      rostest of the nodelet (test_fusion_node: synthetic input, bad input,
#   fusion_node.test           lazy subscription, TF, live parameters, diagnostics); the same test
#   fusion_approx_sync.test    source against the node, and with approximate sync
#   ros_conventions.test     depth_image_proc / stereo_image_proc nodelets consume the outputs by
#                              remapping only; dynparam refusals; silent inputs named
#   rviz_screenshot.test     RViz with rviz/fusion.rviz under Xvfb draws the fused cloud
#   roslaunch-check          every launch file in launch/

find_package(rostest REQUIRED)

set(LSF_ROS_TEST_DEFINITIONS
  LSF_DATA_DIR="${LSF_DATA_DIR}" LSF_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}"
  LSF_BINARY_DIR="${CMAKE_CURRENT_BINARY_DIR}")

catkin_add_gtest(test_ros_unit test/ros/test_conversions_images.cpp
  test/ros/test_conversions_clouds.cpp test/ros/test_conversions_outputs.cpp
  test/ros/test_ros_params.cpp
  test/ros/test_frame_matcher.cpp
  test/ros/test_frame_input.cpp
  test/ros/test_input_attacks.cpp
  test/ros/test_point_time.cpp
  test/ros/test_node_parts.cpp test/ros/test_launch_files.cpp test/ros/run_command.cpp
  test/ros/test_pcl_boundary.cpp
  test/ros/test_recordings_node_unit.cpp
  test/ros/test_rate_governor.cpp)
if(TARGET test_ros_unit)
  # PCL and pcl_conversions: test_pcl_boundary.cpp shows what PCL's conversion does not check.
  target_link_libraries(test_ros_unit ${PROJECT_NAME}_ros ${GTEST_MAIN_LIBRARIES} pcl_common)
  target_include_directories(test_ros_unit SYSTEM PRIVATE ${PCL_INCLUDE_DIRS}
    ${pcl_conversions_INCLUDE_DIRS})
  target_compile_definitions(test_ros_unit PRIVATE ${LSF_ROS_TEST_DEFINITIONS})
endif()

# Synthetic street frames as ROS messages, shared by the rostest nodes.
add_library(${PROJECT_NAME}_ros_test_input STATIC EXCLUDE_FROM_ALL test/ros/synthetic_input.cpp)
target_link_libraries(${PROJECT_NAME}_ros_test_input PUBLIC ${PROJECT_NAME}_ros ${PROJECT_NAME}_sim)

# A rostest gtest node built by `tests` (catkin_make run_tests) after the nodelet and the node.
function(lsf_add_ros_test_node target)
  add_executable(${target} EXCLUDE_FROM_ALL ${ARGN})
  target_link_libraries(${target} ${PROJECT_NAME}_ros_test_input ${GTEST_LIBRARIES})
  target_include_directories(${target} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/test)
  target_include_directories(${target} SYSTEM PRIVATE ${GTEST_INCLUDE_DIRS})
  target_compile_definitions(${target} PRIVATE ${LSF_ROS_TEST_DEFINITIONS})
  add_dependencies(${target} ${PROJECT_NAME}_ros fusion_node)
  if(TARGET tests)
    add_dependencies(tests ${target})
  endif()
endfunction()

# One binary of four sources (any order: each test sets up what it needs); the .test files pick
# tests by --gtest_filter.
lsf_add_ros_test_node(test_fusion_node test/ros/test_fusion_node.cpp
  test/ros/test_fusion_node_input.cpp test/ros/test_fusion_node_params.cpp
  test/ros/test_fusion_node_issues.cpp)
add_rostest(test/ros/fusion_nodelet.test DEPENDENCIES test_fusion_node)
add_rostest(test/ros/fusion_node.test DEPENDENCIES test_fusion_node)
add_rostest(test/ros/fusion_approx_sync.test DEPENDENCIES test_fusion_node)
add_rostest(test/ros/fusion_max_rate.test DEPENDENCIES test_fusion_node)
add_rostest(test/ros/fusion_keep_rate.test DEPENDENCIES test_fusion_node)

# Issue 23: a moving rig's bag (ego-motion on /tf) through the nodelet with and without
# ~fixed_frame, scored against the exact depth at the image instant.
lsf_add_ros_test_node(test_moving_rig test/ros/test_moving_rig.cpp test/ros/child_process.cpp
  test/ros/run_command.cpp)
target_compile_definitions(test_moving_rig PRIVATE LSF_BAG_RUNNER="$<TARGET_FILE:bag_runner>")
add_dependencies(test_moving_rig bag_runner)
add_rostest(test/ros/moving_rig.test DEPENDENCIES test_moving_rig)

# Issue 10: depth_image_proc / stereo_image_proc consume the outputs by remapping only; dynparam
# refusals are visible; silent inputs are named.
lsf_add_ros_test_node(test_ros_conventions test/ros/test_ros_conventions.cpp test/ros/run_command.cpp
  test/ros/child_process.cpp)
add_rostest(test/ros/ros_conventions.test DEPENDENCIES test_ros_conventions)

# RViz with rviz/fusion.rviz under Xvfb: the fused cloud is drawn (screenshots in the build folder).
lsf_add_ros_test_node(test_rviz_screenshot test/ros/test_rviz_screenshot.cpp test/ros/child_process.cpp)
add_rostest(test/ros/rviz_screenshot.test DEPENDENCIES test_rviz_screenshot)

# The simulated street as a live rig: demos, the RViz check, latency and rate measurements.
lsf_add_ros_test_node(synthetic_publisher test/ros/synthetic_publisher.cpp)
lsf_add_ros_test_node(measure_fusion test/ros/measure_fusion.cpp)

# Launch files (tools' launch files too: their executables must exist; measure_live.launch runs
# the test nodes synthetic_publisher and measure_fusion).
find_package(roslaunch REQUIRED)
set(LSF_LAUNCH_CHECK_DEPENDS fusion_node ${PROJECT_NAME}_ros synthetic_publisher measure_fusion)
foreach(tool autoware_calibration_publisher kitti_calibration_publisher)
  if(TARGET ${tool})
    list(APPEND LSF_LAUNCH_CHECK_DEPENDS ${tool})
  endif()
endforeach()
roslaunch_add_file_check(launch IGNORE_UNSET_ARGS DEPENDENCIES ${LSF_LAUNCH_CHECK_DEPENDS})
