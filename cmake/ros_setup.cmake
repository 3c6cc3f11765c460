# ROS 1 (catkin) setup: messages and catkin_package(). Included from the
# top-level CMakeLists.txt before any target when WILD_MVS_WITH_ROS is ON.
find_package(catkin REQUIRED COMPONENTS roscpp std_msgs sensor_msgs
  geometry_msgs message_generation)
catkin_package(
  INCLUDE_DIRS include
  LIBRARIES wild_mvs_core wild_mvs_io
  CATKIN_DEPENDS roscpp std_msgs sensor_msgs geometry_msgs)
