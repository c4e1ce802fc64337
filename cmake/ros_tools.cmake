# Targets of the ROS tools (calibration publishers, bag converter).
