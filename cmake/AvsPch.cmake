# Build time (issue 13 section 5, docs/build.md): unity batches and shared precompiled headers.
#
# Unity build: CMake compiles up to 32 sources of a target per compiler run, so the heavy headers
# are parsed once per batch instead of once per file. On by default for every build (the demo's
# and the test build alike); -DCMAKE_UNITY_BUILD=OFF compiles one file per run, which is what
# shows a file that misses an include of its own.
set(CMAKE_UNITY_BUILD ON CACHE BOOL "Compile up to CMAKE_UNITY_BUILD_BATCH_SIZE sources per compiler run")
set(CMAKE_UNITY_BUILD_BATCH_SIZE 32 CACHE STRING "Sources per unity batch")

# Precompiled headers: the standard library, Eigen and yaml-cpp (and GoogleTest for tests) are
# parsed once for the whole build, by a small host target, and every C++ target reuses that
# parse (REUSE_FROM) instead of parsing them again in each of its compiler runs. Only headers that
# do not change with our code go in, so an edit of ours never rebuilds the PCH.
#
# GCC accepts a PCH only from a compiler run with the same -fpie/-fPIC setting and the same
# predefined macros (definitions of our own may differ), hence one host per kind of target. A PCH
# that GCC refuses is a -Winvalid-pch warning, an error under AVS_WERROR, so CI notices a
# mismatch. It pays in the test build, not in the demo's (docs/build.md): tools/run.sh demo
# turns it off.
option(AVS_PCH "Share precompiled system headers across targets (GCC)" ON)

set(AVS_PCH_HEADERS
  <algorithm> <array> <atomic> <chrono> <cmath> <cstddef> <cstdint> <cstdio> <cstdlib>
  <cstring> <filesystem> <fstream> <functional> <limits> <map> <memory> <mutex> <optional>
  <set> <span> <sstream> <stdexcept> <string> <string_view> <thread> <utility> <vector>
  <Eigen/Core> <Eigen/Geometry> <yaml-cpp/yaml.h>)

# _avs_pch_host(<name> <pic> <glue> <test>): a target that only compiles the PCH, made once.
function(_avs_pch_host name pic glue test)
  if(TARGET ${name})
    return()
  endif()
  set(stub ${CMAKE_BINARY_DIR}/avs_pch/${name}.cpp)
  file(WRITE ${stub} "// Compiles the precompiled headers of cmake/AvsPch.cmake.\n")
  add_library(${name} OBJECT ${stub})
  set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ${pic} UNITY_BUILD OFF)
  target_link_libraries(${name} PRIVATE Eigen3::Eigen yaml-cpp)
  set(headers ${AVS_PCH_HEADERS})
  if(test)
    target_link_libraries(${name} PRIVATE GTest::gtest)
    list(APPEND headers <gtest/gtest.h>)
  endif()
  target_precompile_headers(${name} PRIVATE ${headers})
  # -Wpedantic changes predefined macros (__cpp_runtime_arrays): the host compiles with the
  # project's warning flags, and only targets that have them reuse its PCH. The -O level is
  # the user's too: -O1 test files reusing a -O3 PCH gave GCC 12 -Wstringop-overflow warnings
  # (graph_test.cpp) that they do not give with their own -O1.
  avs_apply_warnings(${name})
  if(glue)
    avs_glue_code(${name})
  endif()
endfunction()

# _avs_targets_below(<out> <dir>): every target defined in <dir> and its subdirectories.
function(_avs_targets_below out dir)
  get_property(targets DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
  get_property(subdirs DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
  foreach(sub ${subdirs})
    _avs_targets_below(below ${sub})
    list(APPEND targets ${below})
  endforeach()
  set(${out} ${targets} PARENT_SCOPE)
endfunction()

# avs_precompile_headers(): called once, after every target is defined (CMakeLists.txt).
function(avs_precompile_headers)
  if(NOT AVS_PCH OR NOT CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    return()
  endif()
  _avs_targets_below(targets ${PROJECT_SOURCE_DIR})
  foreach(target ${targets})
    if(target MATCHES "^avs_pch_")
      continue()
    endif()
    get_target_property(type ${target} TYPE)
    if(NOT type MATCHES "^(STATIC_LIBRARY|OBJECT_LIBRARY|EXECUTABLE)$")
      continue()
    endif()
    # Only targets of C++ sources alone: the host has no C PCH (the IDL libraries have C).
    get_target_property(sources ${target} SOURCES)
    set(c_sources ${sources})
    list(FILTER sources INCLUDE REGEX "\\.(cpp|cc|cxx)$")
    list(FILTER c_sources INCLUDE REGEX "\\.c$")
    if(NOT sources OR c_sources)
      continue()
    endif()
    get_target_property(options ${target} COMPILE_OPTIONS)
    # A code-generation option of its own (avs_sim_core's -fno-math-errno) defines macros the
    # PCH was made without.
    if(NOT options MATCHES "-Wpedantic" OR options MATCHES "(^|;)-f")
      continue()
    endif()
    # PCL, OpenCV and pkg-config packages (Aravis: -pthread) bring compile options of their own.
    get_target_property(links ${target} LINK_LIBRARIES)
    if(links MATCHES "pcl_|opencv_|PCL|OpenCV|PkgConfig::")
      continue()
    endif()
    get_target_property(pic ${target} POSITION_INDEPENDENT_CODE)
    set(host avs_pch)
    if(pic)
      string(APPEND host _pic)
      set(pic ON)
    else()
      string(APPEND host _pie)
      set(pic OFF)
    endif()
    set(glue OFF)
    # avs_glue_code() adds -O1 to a target's own options.
    if(options MATCHES "-O1")
      string(APPEND host _o1)
      set(glue ON)
    endif()
    set(test OFF)
    if(TARGET GTest::gtest AND links MATCHES "GTest::")
      string(APPEND host _test)
      set(test ON)
    endif()
    _avs_pch_host(${host} ${pic} ${glue} ${test})
    target_precompile_headers(${target} REUSE_FROM ${host})
  endforeach()
endfunction()
