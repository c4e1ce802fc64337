# Tests of the ROS tools (calibration publishers, KITTI -> bag converter). Included after the core
# tests when testing is enabled, with catkin set up and the tool targets defined.

find_package(rostest REQUIRED)

# Compile definitions and includes shared by the tools' tests.
function(lsf_tools_test_setup target)
  target_link_libraries(${target} ${PROJECT_NAME}_calibration_msgs ${GTEST_LIBRARIES})
  target_include_directories(${target} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/test)
  target_include_directories(${target} SYSTEM PRIVATE ${GTEST_INCLUDE_DIRS})
  target_compile_definitions(${target} PRIVATE
    LSF_DATA_DIR="${LSF_DATA_DIR}" LSF_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}"
    LSF_BINARY_DIR="${CMAKE_CURRENT_BINARY_DIR}")
endfunction()

# A gtest executable run by rostest with the launch file `launch_file`; built by `tests`
# (catkin_make run_tests / tests), after the executables in DEPENDS. With DATA_DIR_ARG the launch
# file gets data_dir:=LSF_DATA_DIR.
function(lsf_add_tools_rostest target launch_file)
  cmake_parse_arguments(arg "DATA_DIR_ARG" "" "SOURCES;DEPENDS" ${ARGN})
  add_executable(${target} EXCLUDE_FROM_ALL ${arg_SOURCES})
  lsf_tools_test_setup(${target})
  if(arg_DEPENDS)
    add_dependencies(${target} ${arg_DEPENDS})
  endif()
  if(TARGET tests)
    add_dependencies(tests ${target})
  endif()
  if(arg_DATA_DIR_ARG)
    add_rostest(${launch_file} ARGS data_dir:=${LSF_DATA_DIR} DEPENDENCIES ${target})
  else()
    add_rostest(${launch_file} DEPENDENCIES ${target})
  endif()
endfunction()

# Issue 33: bag_runner's files (outputs apart from inputs, temporary names, manifest); no master.
catkin_add_gtest(test_bag_files test/ros/test_bag_files.cpp)
if(TARGET test_bag_files)
  lsf_tools_test_setup(test_bag_files)
  target_link_libraries(test_bag_files ${PROJECT_NAME}_bag ${GTEST_MAIN_LIBRARIES})
endif()

# Direction and content of the TF / camera_info messages (tf2 buffer, no ROS master).
catkin_add_gtest(test_calibration_msgs test/ros/test_calibration_msgs.cpp)
if(TARGET test_calibration_msgs)
  lsf_tools_test_setup(test_calibration_msgs)
endif()

# The calibration publishers on the real Autoware and KITTI calibrations.
lsf_add_tools_rostest(test_calibration_publishers test/ros/calibration_publishers.test DATA_DIR_ARG
  SOURCES test/ros/test_calibration_publishers.cpp test/ros/run_command.cpp
  DEPENDS autoware_calibration_publisher kitti_calibration_publisher)
target_compile_definitions(test_calibration_publishers PRIVATE
  LSF_AUTOWARE_PUBLISHER="$<TARGET_FILE:autoware_calibration_publisher>"
  LSF_KITTI_PUBLISHER="$<TARGET_FILE:kitti_calibration_publisher>")

# KITTI raw -> kitti_to_bag -> the fusion nodelet, compared with the offline kitti_runner.
if(TARGET kitti_runner)
  lsf_add_tools_rostest(test_kitti_bag test/ros/kitti_bag.test
    SOURCES test/ros/test_kitti_bag.cpp test/ros/test_kitti_bag_replay.cpp
            test/ros/kitti_bag_expected.cpp test/ros/kitti_bag_util.cpp test/ros/run_command.cpp
            test/ros/depth_agreement.cpp test/ros/bag_runner_check.cpp test/ros/child_process.cpp
    DEPENDS kitti_to_bag kitti_runner bag_runner ${PROJECT_NAME}_ros ${PROJECT_NAME}_generate_messages_cpp)
  target_include_directories(test_kitti_bag SYSTEM PRIVATE
    ${CATKIN_DEVEL_PREFIX}/${CATKIN_GLOBAL_INCLUDE_DESTINATION})  # FusionStats.h
  target_compile_definitions(test_kitti_bag PRIVATE
    LSF_KITTI_TO_BAG="$<TARGET_FILE:kitti_to_bag>" LSF_KITTI_RUNNER="$<TARGET_FILE:kitti_runner>"
    LSF_BAG_RUNNER="$<TARGET_FILE:bag_runner>")
  lsf_add_tools_rostest(test_kitti_bag_rates test/ros/kitti_bag_rates.test
    SOURCES test/ros/test_kitti_bag_rates.cpp test/ros/kitti_bag_expected.cpp
            test/ros/kitti_bag_util.cpp test/ros/run_command.cpp test/ros/child_process.cpp
    DEPENDS kitti_to_bag ${PROJECT_NAME}_ros ${PROJECT_NAME}_generate_messages_cpp)
  target_include_directories(test_kitti_bag_rates SYSTEM PRIVATE
    ${CATKIN_DEVEL_PREFIX}/${CATKIN_GLOBAL_INCLUDE_DESTINATION})  # FusionStats.h
  target_compile_definitions(test_kitti_bag_rates PRIVATE
    LSF_KITTI_TO_BAG="$<TARGET_FILE:kitti_to_bag>")
  # kitti_to_bag --period / --cycles: stamps of the restamped, repeated stream (no ROS master).
  catkin_add_gtest(test_kitti_to_bag_stream test/ros/test_kitti_to_bag_stream.cpp
    test/ros/kitti_bag_util.cpp test/ros/run_command.cpp)
  if(TARGET test_kitti_to_bag_stream)
    lsf_tools_test_setup(test_kitti_to_bag_stream)
    add_dependencies(test_kitti_to_bag_stream kitti_to_bag)
    target_compile_definitions(test_kitti_to_bag_stream PRIVATE
      LSF_KITTI_TO_BAG="$<TARGET_FILE:kitti_to_bag>")
  endif()
  # playback.launch on a KITTI bag: to the end (fusion and RViz stay) and looped (issue 10).
  lsf_add_tools_rostest(test_playback test/ros/playback.test
    SOURCES test/ros/test_playback.cpp test/ros/kitti_bag_util.cpp test/ros/run_command.cpp
            test/ros/child_process.cpp
    DEPENDS kitti_to_bag fusion_node ${PROJECT_NAME}_ros ${PROJECT_NAME}_generate_messages_cpp)
  target_include_directories(test_playback SYSTEM PRIVATE
    ${CATKIN_DEVEL_PREFIX}/${CATKIN_GLOBAL_INCLUDE_DESTINATION})  # FusionStats.h
  target_compile_definitions(test_playback PRIVATE LSF_KITTI_TO_BAG="$<TARGET_FILE:kitti_to_bag>")
  # Issue 26: pcl_ros's CropBox (sweep) and VoxelGrid (points2) in the fusion's manager.
  lsf_add_tools_rostest(test_pcl_filters test/ros/pcl_filters.test
    SOURCES test/ros/test_pcl_filters.cpp test/ros/kitti_bag_util.cpp test/ros/run_command.cpp
            test/ros/child_process.cpp
    DEPENDS kitti_to_bag ${PROJECT_NAME}_ros ${PROJECT_NAME}_generate_messages_cpp)
  target_include_directories(test_pcl_filters SYSTEM PRIVATE
    ${CATKIN_DEVEL_PREFIX}/${CATKIN_GLOBAL_INCLUDE_DESTINATION} ${PCL_INCLUDE_DIRS}
    ${pcl_conversions_INCLUDE_DIRS})
  target_link_libraries(test_pcl_filters pcl_filters pcl_common)
  target_compile_definitions(test_pcl_filters PRIVATE LSF_KITTI_TO_BAG="$<TARGET_FILE:kitti_to_bag>")
else()
  message(WARNING "no kitti_runner target (tools/kitti_runner.cpp): test/ros/kitti_bag.test is "
                  "not registered")
endif()

# bag_runner and lsf_batch on small KITTI bags (pytest; lsf_batch on a LocalCluster of 2 worker
# processes): batch == serial, a killed worker, chunks, resume, bad bags, other rigs' topics.
# run_tests.py runs the command as one shell string (as catkin_add_nosetests does).
catkin_run_tests_target("pytest" "lsf_batch" "pytest-lsf_batch.xml"
  COMMAND "${CMAKE_COMMAND} -E env LSF_DATA_DIR=${LSF_DATA_DIR} LSF_BIN_DIR=$<TARGET_FILE_DIR:bag_runner> LSF_SCRATCH=${CMAKE_CURRENT_BINARY_DIR}/test_lsf_batch ${PYTHON_EXECUTABLE} -m pytest -q -p no:cacheprovider --junitxml=${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/pytest-lsf_batch.xml ${CMAKE_CURRENT_SOURCE_DIR}/test/ros/test_lsf_batch.py"
  DEPENDENCIES bag_runner kitti_to_bag)

# Issue 33: recordings as users keep them; pytest, bags written at test time into the build
# folder, one pytest command (the modules share its bags: test/ros/bag_tool_setup.py):
#   test_recordings_outputs.py  outputs apart from inputs, resume with a manifest, a killed run's
#                               temporary files, an unwritable folder, the PCD layout;
#   test_recordings_inputs.py   compressed images, a swapped pair, fusion.launch's box corners,
#                               remaps, bad bags, empty windows;
#   test_recordings_batch.py    a lost or unreachable scheduler, the chunk floor.
set(LSF_RECORDINGS_TESTS "")
foreach(part outputs inputs batch)
  string(APPEND LSF_RECORDINGS_TESTS
         " ${CMAKE_CURRENT_SOURCE_DIR}/test/ros/test_recordings_${part}.py")
endforeach()
catkin_run_tests_target("pytest" "recordings" "pytest-recordings.xml"
  COMMAND "${CMAKE_COMMAND} -E env LSF_DATA_DIR=${LSF_DATA_DIR} LSF_BIN_DIR=$<TARGET_FILE_DIR:bag_runner> LSF_SCRATCH=${CMAKE_CURRENT_BINARY_DIR}/test_recordings ${PYTHON_EXECUTABLE} -m pytest -q -p no:cacheprovider --junitxml=${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/pytest-recordings.xml${LSF_RECORDINGS_TESTS}"
  DEPENDENCIES bag_runner kitti_to_bag)

# Issue 33, the live node: playback.launch image_transport:=compressed on compressed KITTI bags
# (png: the raw depth, jpeg: within the stated tolerance), a transport without its plugin, a
# swapped pair, a remap naming nothing of the node; pytest with its own roscore.
catkin_run_tests_target("pytest" "recordings_node" "pytest-recordings_node.xml"
  COMMAND "${CMAKE_COMMAND} -E env LSF_DATA_DIR=${LSF_DATA_DIR} LSF_BIN_DIR=$<TARGET_FILE_DIR:bag_runner> LSF_SCRATCH=${CMAKE_CURRENT_BINARY_DIR}/test_recordings_node ${PYTHON_EXECUTABLE} -m pytest -q -p no:cacheprovider --junitxml=${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/pytest-recordings_node.xml ${CMAKE_CURRENT_SOURCE_DIR}/test/ros/test_recordings_node.py"
  DEPENDENCIES bag_runner kitti_to_bag fusion_node ${PROJECT_NAME}_ros)
