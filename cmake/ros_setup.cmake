# ROS 1 (catkin) setup: messages, services and catkin_package(). Included from
# the top-level CMakeLists.txt before any target when WILD_MVS_WITH_ROS is ON.
# The targets (nodes, nodelets, rostests) are in cmake/ros_nodes.cmake.
#
# Only what the ROS layer really uses is asked for: no cv_bridge (images are
# converted by src/ros/conversions.cpp, which validates every field), no
# pcl_ros (PointCloud2 is filled directly).
# The devel space: rosrun skips every executable under <package>/build/
# (its `find ! -regex ".*$pkgdir/build/.*"`), so the README's build folder
# <source>/build keeps its devel space beside it, in <source>/devel (git
# ignores it). Other build folders (build-fuzz, out-of-tree) keep the
# catkin default <build>/devel. An explicit -DCATKIN_DEVEL_PREFIX wins.
if(NOT CATKIN_DEVEL_PREFIX AND
   CMAKE_BINARY_DIR STREQUAL "${CMAKE_SOURCE_DIR}/build")
  set(CATKIN_DEVEL_PREFIX "${CMAKE_SOURCE_DIR}/devel")
endif()

set(WILD_MVS_ROS_COMPONENTS
  roscpp nodelet pluginlib std_msgs std_srvs sensor_msgs geometry_msgs nav_msgs
  dynamic_reconfigure
  visualization_msgs diagnostic_msgs diagnostic_updater image_transport
  tf2 tf2_ros tf2_msgs rosbag message_generation)
# catkin installs its setup files (setup.bash, _setup_util.py, ...) to the
# absolute CMAKE_INSTALL_PREFIX of configure time, which
# `cmake --install build --prefix P` does not move: they are installed
# below with relative destinations instead, so that any prefix works.
if(NOT DEFINED CATKIN_INSTALL_INTO_PREFIX_ROOT)
  set(CATKIN_INSTALL_INTO_PREFIX_ROOT FALSE)
  set(WILD_MVS_INSTALL_SETUP_FILES ON)
endif()
find_package(catkin REQUIRED COMPONENTS ${WILD_MVS_ROS_COMPONENTS})
if(WILD_MVS_INSTALL_SETUP_FILES AND NOT CMAKE_INSTALL_PREFIX STREQUAL "/usr")
  set(_ws ${CMAKE_BINARY_DIR}/catkin_generated/installspace)
  install(CODE "
    if(NOT EXISTS \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/.catkin\")
      file(WRITE \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/.catkin\" \"\")
    endif()")
  # the devel space's _setup_util.py comes from the same template with the
  # same values (it finds its workspace from its own location)
  install(PROGRAMS ${CATKIN_DEVEL_PREFIX}/_setup_util.py ${_ws}/env.sh
    DESTINATION .)
  install(FILES ${_ws}/setup.bash ${_ws}/setup.sh ${_ws}/setup.zsh
    ${_ws}/local_setup.bash ${_ws}/local_setup.sh ${_ws}/local_setup.zsh
    ${_ws}/.rosinstall DESTINATION .)
endif()

add_message_files(DIRECTORY msg FILES
  DepthView.msg TrackedPoint.msg SparsePoints.msg SelectedKeyframe.msg KeyframeIndex.msg)
add_service_files(DIRECTORY srv FILES SaveCloud.srv GetKeyframe.srv)
generate_messages(DEPENDENCIES std_msgs sensor_msgs geometry_msgs)

catkin_package(
  INCLUDE_DIRS include
  LIBRARIES wild_mvs_core wild_mvs_io wild_mvs_pipeline wild_mvs_stream wild_mvs_ros
  CATKIN_DEPENDS roscpp nodelet std_msgs std_srvs sensor_msgs geometry_msgs nav_msgs
    dynamic_reconfigure
    visualization_msgs diagnostic_msgs diagnostic_updater image_transport
    tf2 tf2_ros tf2_msgs rosbag message_runtime)
