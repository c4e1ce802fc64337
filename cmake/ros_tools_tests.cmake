# Tests of the ROS tools.
