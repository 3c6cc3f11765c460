# libFuzzer harnesses for every reader (included when -DWILD_MVS_FUZZ=ON).
#
# Configure with clang (scripts/run_fuzz.sh does it in build-fuzz/):
#   cmake -S . -B build-fuzz -DCMAKE_CXX_COMPILER=clang++ -DWILD_MVS_FUZZ=ON \
#         -DWILD_MVS_WITH_ROS=OFF
# Every target of the project is then built with AddressSanitizer and
# UndefinedBehaviorSanitizer (the unit and CLI tests of this build are the
# sanitizer step of scripts/run_sanitizers.sh), the library code also with
# libFuzzer's coverage instrumentation, and each
# test/fuzz/fuzz_<name>.cpp becomes an executable fuzz_<name> (a libFuzzer
# binary; run it with a corpus folder, see scripts/run_fuzz.sh). With
# WILD_MVS_WITH_ROS=ON, test/fuzz/ros/fuzz_ros_messages.cpp (the nodes'
# message decoding, src/ros/conversions.cpp over src/io/pixel_buffer.cpp) is
# built too. The target `fuzzers` builds all harnesses into
# ${CMAKE_BINARY_DIR}/fuzz/.
if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(FATAL_ERROR "WILD_MVS_FUZZ=ON needs clang "
          "(-DCMAKE_CXX_COMPILER=clang++); got ${CMAKE_CXX_COMPILER_ID}")
endif()

# EIGEN_MALLOC_ALREADY_ALIGNED=1: under ASan Eigen stops trusting malloc's
# 16-byte alignment and frees with its own header, while Debian's
# (unsanitized) PCL allocates Eigen-aligned objects with plain malloc;
# freeing a PCL cloud in MeshPointCloud then reads before the block. Keep
# the normal builds' choice so that both sides agree.
set(WILD_MVS_FUZZ_SANITIZERS -fsanitize=address,undefined
    -fno-sanitize-recover=undefined -fno-omit-frame-pointer
    -DEIGEN_MALLOC_ALREADY_ALIGNED=1)

# Sanitize everything already defined (libraries, tool, tests, benchmarks).
get_property(_wild_mvs_targets DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}
             PROPERTY BUILDSYSTEM_TARGETS)
foreach(t ${_wild_mvs_targets})
  get_target_property(_type ${t} TYPE)
  if(_type MATCHES "^(STATIC_LIBRARY|SHARED_LIBRARY|OBJECT_LIBRARY|EXECUTABLE)$")
    target_compile_options(${t} PRIVATE ${WILD_MVS_FUZZ_SANITIZERS})
    target_link_options(${t} PRIVATE -fsanitize=address,undefined)
  endif()
endforeach()
# Coverage feedback for the code under test: the readers (io) and the
# config (cli). Not the core: the fuzzed readers barely reach it, and its
# instrumented MVS loops would make the sanitizer step's tests 2-3x slower.
foreach(lib wild_mvs_io wild_mvs_cli)
  if(TARGET ${lib})
    target_compile_options(${lib} PRIVATE -fsanitize=fuzzer-no-link)
  endif()
endforeach()

add_custom_target(fuzzers)
file(GLOB WILD_MVS_FUZZ_HARNESSES CONFIGURE_DEPENDS test/fuzz/fuzz_*.cpp)
if(WILD_MVS_WITH_ROS AND TARGET ${PROJECT_NAME}_generate_messages_cpp)
  list(APPEND WILD_MVS_FUZZ_HARNESSES
       ${CMAKE_CURRENT_SOURCE_DIR}/test/fuzz/ros/fuzz_ros_messages.cpp)
endif()
foreach(src ${WILD_MVS_FUZZ_HARNESSES})
  get_filename_component(name ${src} NAME_WE)
  set(extra)
  if(name STREQUAL "fuzz_ros_messages")
    # Compiled into the harness (with coverage) rather than linking the
    # whole ROS layer library.
    set(extra ${CMAKE_CURRENT_SOURCE_DIR}/src/ros/conversions.cpp)
  endif()
  add_executable(${name} ${src} ${extra})
  target_include_directories(${name} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/test/fuzz
                             ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_compile_options(${name} PRIVATE -fsanitize=fuzzer
                         ${WILD_MVS_FUZZ_SANITIZERS} ${WILD_MVS_WARNINGS})
  target_link_options(${name} PRIVATE -fsanitize=fuzzer,address,undefined)
  target_link_libraries(${name} PRIVATE wild_mvs_io)
  if(name STREQUAL "fuzz_yaml_config")
    target_link_libraries(${name} PRIVATE wild_mvs_cli)  # OptionSet, config
  endif()
  set_target_properties(${name} PROPERTIES
    RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/fuzz)
  if(name STREQUAL "fuzz_ros_messages")
    target_include_directories(${name} PRIVATE
      ${CATKIN_DEVEL_PREFIX}/${CATKIN_GLOBAL_INCLUDE_DESTINATION})
    target_include_directories(${name} SYSTEM PRIVATE ${catkin_INCLUDE_DIRS})
    target_link_libraries(${name} PRIVATE ${catkin_LIBRARIES})
    add_dependencies(${name} ${PROJECT_NAME}_generate_messages_cpp)
  endif()
  add_dependencies(fuzzers ${name})
endforeach()
