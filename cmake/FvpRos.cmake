# Debian 12's ROS 1, found by hand, not through catkin's CMake configs: Debian's rosbag_storage
# config pulls in ROS 2's pluginlib (ament), whose CMake needs ament's Python tooling, and its
# pkg-config files require a pluginlib.pc Debian does not ship. Used by ros/ and the fuzz build.
set(FVP_ROS_LIBRARIES rosbag_storage roscpp_serialization rostime cpp_common tf2 cv_bridge
    console_bridge class_loader)
set(FVP_ROS_HEADERS rosbag/bag.h tf2/buffer_core.h cv_bridge/cv_bridge.h sensor_msgs/Image.h
    stereo_msgs/DisparityImage.h tf2_msgs/TFMessage.h pluginlib/class_loader.hpp class_loader/class_loader.hpp
    rcutils/types.h rcpputils/shared_library.hpp ament_index_cpp/get_resource.hpp)

# fvp_ros_find(<found_var>): the libraries as imported targets and the header directories, or
# <found_var> FALSE with what is missing in FVP_ROS_MISSING.
function(fvp_ros_find found_var)
  set(missing)
  set(include_dirs)
  foreach(header ${FVP_ROS_HEADERS})
    string(MAKE_C_IDENTIFIER ${header} id)
    get_filename_component(sub ${header} DIRECTORY)
    find_path(FVP_ROS_INCLUDE_${id} ${header} PATH_SUFFIXES ${sub})
    if(NOT FVP_ROS_INCLUDE_${id})
      list(APPEND missing ${header})
    else()
      list(APPEND include_dirs ${FVP_ROS_INCLUDE_${id}})
    endif()
  endforeach()
  set(libraries)
  foreach(lib ${FVP_ROS_LIBRARIES})
    find_library(FVP_ROS_LIB_${lib} ${lib})
    if(NOT FVP_ROS_LIB_${lib})
      list(APPEND missing lib${lib})
    else()
      list(APPEND libraries ${FVP_ROS_LIB_${lib}})
    endif()
  endforeach()
  list(REMOVE_DUPLICATES include_dirs)
  set(FVP_ROS_MISSING "${missing}" PARENT_SCOPE)
  set(FVP_ROS_INCLUDE_DIRS "${include_dirs}" PARENT_SCOPE)
  set(FVP_ROS_LINK "${libraries}" PARENT_SCOPE)
  if(missing)
    set(${found_var} FALSE PARENT_SCOPE)
  else()
    set(${found_var} TRUE PARENT_SCOPE)
  endif()
endfunction()
