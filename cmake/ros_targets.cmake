# Targets of the ROS layer (nodelet, nodes). Included after the core targets.
