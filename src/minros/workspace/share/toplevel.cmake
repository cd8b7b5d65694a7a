# Top-level CMakeLists.txt of a catkin workspace (installed by minros's catkin_init_workspace).
# minros's catkin_make does not run CMake; this file lets a real catkin build the same workspace:
# it looks for catkin in the workspace itself or in CMAKE_PREFIX_PATH and hands over to it.
cmake_minimum_required(VERSION 3.0.2)
project(Project)

set(CATKIN_TOPLEVEL TRUE)

if(EXISTS "${CMAKE_SOURCE_DIR}/catkin/cmake/all.cmake" AND EXISTS "${CMAKE_SOURCE_DIR}/catkin/package.xml")
  message(STATUS "Using catkin from the source space: ${CMAKE_SOURCE_DIR}/catkin")
  include("${CMAKE_SOURCE_DIR}/catkin/cmake/all.cmake")
  add_subdirectory(catkin)
else()
  set(_cmake_prefix_path "$ENV{CMAKE_PREFIX_PATH}")
  string(REPLACE ":" ";" _cmake_prefix_path "${_cmake_prefix_path}")
  find_package(catkin QUIET NO_POLICY_SCOPE PATHS ${_cmake_prefix_path} NO_DEFAULT_PATH)
  if(NOT catkin_FOUND)
    message(FATAL_ERROR "catkin was not found in the workspace nor in CMAKE_PREFIX_PATH; "
      "use minros's catkin_make, which needs no CMake, or install catkin")
  endif()
  catkin_workspace()
endif()
