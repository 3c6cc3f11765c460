# ROS 1 targets: the ROS layer library (conversions, parameters, nodelets
# over the ROS-free wild_mvs_stream), node executables, the bag
# converter, and the ROS tests. Included at the end of the top-level
# CMakeLists.txt when WILD_MVS_WITH_ROS is ON (after cmake/ros_setup.cmake).
#
# Test executables are ordinary targets (built by `all`), so a plain
# `cmake --build build && ctest` runs the ROS tests too; `--target tests`
# builds them as well.

# --- the ROS layer ---------------------------------------------------------
file(GLOB WILD_MVS_ROS_SRC CONFIGURE_DEPENDS src/ros/*.cpp)
add_library(wild_mvs_ros SHARED ${WILD_MVS_ROS_SRC})
target_include_directories(wild_mvs_ros PUBLIC
  $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
  ${CATKIN_DEVEL_PREFIX}/${CATKIN_GLOBAL_INCLUDE_DESTINATION})
target_include_directories(wild_mvs_ros SYSTEM PUBLIC ${catkin_INCLUDE_DIRS})
target_link_libraries(wild_mvs_ros PUBLIC wild_mvs_stream ${catkin_LIBRARIES})
target_compile_options(wild_mvs_ros PRIVATE ${WILD_MVS_WARNINGS})
add_dependencies(wild_mvs_ros ${PROJECT_NAME}_generate_messages_cpp
  ${catkin_EXPORTED_TARGETS})

# --- nodes and tools ---------------------------------------------------------
set(WILD_MVS_ROS_EXECUTABLES)
foreach(name depth_node keyframe_selector_node depth_worker_node fusion_node
    wild_mvs_to_bag)
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/src/nodes/${name}.cpp)
    add_executable(${name} src/nodes/${name}.cpp)
    target_link_libraries(${name} PRIVATE wild_mvs_ros)
    target_compile_options(${name} PRIVATE ${WILD_MVS_WARNINGS})
    list(APPEND WILD_MVS_ROS_EXECUTABLES ${name})
  endif()
endforeach()
# Writes config/*.yaml (reconstruct, the depth roles, fusion) from the option
# registry (`wild_mvs_write_config config`; the test config_files compares).
add_executable(wild_mvs_write_config src/tools/write_config.cpp)
target_link_libraries(wild_mvs_write_config PRIVATE wild_mvs_ros wild_mvs_cli)
target_compile_options(wild_mvs_write_config PRIVATE ${WILD_MVS_WARNINGS})
# bench/run_live.sh: the depth maps a live run published, as a reconstruct
# folder for `wild_mvs eval depth` (not installed).
add_executable(bench_live_depth_maps bench/ros/live_depth_maps.cpp)
target_link_libraries(bench_live_depth_maps PRIVATE wild_mvs_ros wild_mvs_io)
target_compile_options(bench_live_depth_maps PRIVATE ${WILD_MVS_WARNINGS})
if(TARGET wild_mvs_to_bag)
  # `wild_mvs to-bag` finds it beside build/bin/wild_mvs.
  add_custom_command(TARGET wild_mvs_to_bag POST_BUILD
    COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_BINARY_DIR}/bin
    COMMAND ${CMAKE_COMMAND} -E create_symlink $<TARGET_FILE:wild_mvs_to_bag>
            ${CMAKE_BINARY_DIR}/bin/wild_mvs_to_bag)
endif()

# --- install space -------------------------------------------------------------
# `cmake --install build --prefix P` gives a self-contained catkin install
# space (source P/setup.bash; rosrun / roslaunch / nodelet from there). The
# core, io and stream libraries are static and PIC, linked into
# libwild_mvs_ros.so, the nodes and the CLI; they and the headers are
# installed for packages that build on wild_mvs (catkin_package LIBRARIES).
# The installed binaries are relocatable: the nodes and tools
# (lib/wild_mvs/ of the devel or install space) and the libraries (lib/)
# find the project's libraries in lib/ through $ORIGIN, the same way in the
# devel space and after `cmake --install` (no RPATH rewrite at install
# time, which fails on catkin's build RPATH). Tests and fuzz harnesses keep
# CMake's build RPATH.
set(WILD_MVS_INSTALLED_TARGETS ${WILD_MVS_ROS_EXECUTABLES} wild_mvs wild_mvs_ros
  wild_mvs_core wild_mvs_io wild_mvs_pipeline wild_mvs_stream)
set_target_properties(${WILD_MVS_INSTALLED_TARGETS} PROPERTIES
  BUILD_WITH_INSTALL_RPATH ON INSTALL_RPATH "$ORIGIN/..;$ORIGIN/../lib")
install(TARGETS ${WILD_MVS_ROS_EXECUTABLES}
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
install(TARGETS wild_mvs_ros wild_mvs_core wild_mvs_io wild_mvs_pipeline wild_mvs_stream
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  RUNTIME DESTINATION ${CATKIN_GLOBAL_BIN_DESTINATION})
# The CLI in P/bin (on PATH after sourcing P/setup.bash); `wild_mvs to-bag`
# finds P/lib/wild_mvs/wild_mvs_to_bag from there.
install(TARGETS wild_mvs RUNTIME DESTINATION ${CATKIN_GLOBAL_BIN_DESTINATION})
install(DIRECTORY include/ DESTINATION ${CATKIN_GLOBAL_INCLUDE_DESTINATION})
install(DIRECTORY launch config
  DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})
install(FILES nodelet_plugins.xml
  DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})
# (package.xml, the messages and the service are installed by catkin.)
catkin_install_python(PROGRAMS src/nodes/finish_when_idle.py
  src/nodes/pose_to_tf.py src/nodes/camera_info_publisher.py
  DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# --- tests -------------------------------------------------------------------
if(WILD_MVS_BUILD_TESTS AND CATKIN_ENABLE_TESTING)
  # Plain gtests of the ROS layer (no master needed).
  file(GLOB WILD_MVS_ROS_UNIT_TESTS CONFIGURE_DEPENDS test/ros/test_*.cpp)
  foreach(src ${WILD_MVS_ROS_UNIT_TESTS})
    get_filename_component(name ${src} NAME_WE)
    set(name ros_${name})
    add_executable(${name} ${src})
    target_link_libraries(${name} PRIVATE wild_mvs_ros wild_mvs_test_support
      yaml-cpp GTest::gtest GTest::gtest_main)
    target_compile_definitions(${name} PRIVATE
      WILD_MVS_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
    target_compile_options(${name} PRIVATE ${WILD_MVS_WARNINGS})
    # One ctest test per gtest case, ros_<executable>.<Suite>.<Case>
    # (skips show as skipped; see the unit tests in CMakeLists.txt).
    gtest_discover_tests(${name} TEST_PREFIX "${name}." DISCOVERY_MODE PRE_TEST
      DISCOVERY_TIMEOUT 120 PROPERTIES TIMEOUT 300)
  endforeach()

  # rostests: each test/ros/*.test launches the nodes and a checker node
  # built from test/ros/rostest_<name>.cpp (when present).
  find_package(rostest REQUIRED)
  file(GLOB WILD_MVS_ROSTEST_CHECKERS CONFIGURE_DEPENDS
    test/ros/rostest_*.cpp)
  set(WILD_MVS_ROSTEST_TARGETS)
  foreach(src ${WILD_MVS_ROSTEST_CHECKERS})
    get_filename_component(name ${src} NAME_WE)
    add_executable(${name} ${src})
    target_link_libraries(${name} PRIVATE wild_mvs_ros wild_mvs_test_support
      GTest::gtest)
    target_compile_options(${name} PRIVATE ${WILD_MVS_WARNINGS})
    list(APPEND WILD_MVS_ROSTEST_TARGETS ${name})
  endforeach()
  # The parameters checker compares with the CLI's reading of the files.
  if(TARGET rostest_params)
    target_link_libraries(rostest_params PRIVATE wild_mvs_cli)
    target_compile_definitions(rostest_params PRIVATE
      WILD_MVS_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
  endif()
  # Every launch file parses and names only nodes of packages that
  # package.xml declares (roslaunch-check; -i: `bag`, `index`, `count` have
  # no default). test/ros/test_launch_files.sh then expands them with
  # arguments (roslaunch --nodes / --dump-params).
  find_package(roslaunch REQUIRED)
  roslaunch_add_file_check(launch IGNORE_UNSET_ARGS)
  # roslaunch-check runs `python3` from PATH: Debian's, not a pyenv one.
  set_tests_properties(_ctest_${PROJECT_NAME}_roslaunch-check_launch PROPERTIES
    ENVIRONMENT "PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin")
  add_test(NAME ros_launch_files
    COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test/ros/test_launch_files.sh
            ${CATKIN_DEVEL_PREFIX})
  set_tests_properties(ros_launch_files PROPERTIES TIMEOUT 120)

  # The devel space and the install space work with the standard tools:
  # rosrun of the nodes and a nodelet from another directory, and
  # `cmake --install` to a temporary prefix, then rosrun from there.
  foreach(space devel install)
    add_test(NAME ros_${space}_space
      COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test/ros/test_${space}_space.sh
              ${CMAKE_BINARY_DIR} ${CATKIN_DEVEL_PREFIX})
    set_tests_properties(ros_${space}_space PROPERTIES TIMEOUT 300)
  endforeach()
  # config/*.yaml are what wild_mvs_write_config writes (the registry).
  add_test(NAME config_files
    COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test/ros/test_config_files.sh
            $<TARGET_FILE:wild_mvs_write_config>
            ${CMAKE_CURRENT_SOURCE_DIR}/config)
  set_tests_properties(config_files PROPERTIES TIMEOUT 60)
  # reconstruct_bag.launch on a bag with other topic names ends by itself.
  add_test(NAME ros_own_bag
    COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test/ros/test_own_bag.sh
            ${CATKIN_DEVEL_PREFIX} ${CMAKE_CURRENT_SOURCE_DIR})
  set_tests_properties(ros_own_bag PROPERTIES TIMEOUT 600)

  # `wild_mvs to-bag` writes a rendered dataset as a bag; the bag is read
  # back (rosbag info, python3-rosbag) and compared with the dataset.
  add_test(NAME ros_to_bag
    COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/test/ros/test_to_bag.sh
            $<TARGET_FILE:wild_mvs> $<TARGET_FILE:make_scene>
            ${CATKIN_DEVEL_PREFIX})
  set_tests_properties(ros_to_bag PROPERTIES TIMEOUT 300)

  file(GLOB WILD_MVS_ROSTESTS CONFIGURE_DEPENDS test/ros/*.test)
  foreach(file ${WILD_MVS_ROSTESTS})
    add_rostest(${file} DEPENDENCIES ${WILD_MVS_ROSTEST_TARGETS}
      ${WILD_MVS_ROS_EXECUTABLES})
  endforeach()
endif()
