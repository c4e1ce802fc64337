# rostests of the ROS layer. Included after the core tests when testing is enabled.
