# Debian 12's ROS 1, found by hand, not through catkin's CMake configs: Debian's rosbag_storage
# config pulls in ROS 2's pluginlib (ament), whose CMake needs ament's Python tooling, and its
# pkg-config files require a pluginlib.pc Debian does not ship. Used by ros/ and the fuzz build.
set(FVP_ROS_LIBRARIES rosbag_storage roscpp_serialization rostime cpp_common tf2 cv_bridge
    console_bridge class_loader)
set(FVP_ROS_HEADERS rosbag/bag.h tf2/buffer_core.h cv_bridge/cv_bridge.h sensor_msgs/Image.h
    visualization_msgs/MarkerArray.h
    stereo_msgs/DisparityImage.h tf2_msgs/TFMessage.h pluginlib/class_loader.hpp class_loader/class_loader.hpp
    rcutils/types.h rcpputils/shared_library.hpp ament_index_cpp/get_resource.hpp)

# _fvp_ros_find_set(<prefix> HEADERS ... LIBRARIES ...): each header's directory and each library,
# in <prefix>_INCLUDE_DIRS and <prefix>_LINK; what is missing in <prefix>_MISSING.
function(_fvp_ros_find_set prefix)
  cmake_parse_arguments(ARG "" "" "HEADERS;LIBRARIES" ${ARGN})
  set(missing)
  set(include_dirs)
  foreach(header ${ARG_HEADERS})
    string(MAKE_C_IDENTIFIER ${header} id)
    get_filename_component(sub ${header} DIRECTORY)
    find_path(${prefix}_INCLUDE_${id} ${header} PATH_SUFFIXES ${sub})
    if(NOT ${prefix}_INCLUDE_${id})
      list(APPEND missing ${header})
    else()
      list(APPEND include_dirs ${${prefix}_INCLUDE_${id}})
    endif()
  endforeach()
  set(libraries)
  foreach(lib ${ARG_LIBRARIES})
    find_library(${prefix}_LIB_${lib} ${lib})
    if(NOT ${prefix}_LIB_${lib})
      list(APPEND missing lib${lib})
    else()
      list(APPEND libraries ${${prefix}_LIB_${lib}})
    endif()
  endforeach()
  list(REMOVE_DUPLICATES include_dirs)
  set(${prefix}_MISSING "${missing}" PARENT_SCOPE)
  set(${prefix}_INCLUDE_DIRS "${include_dirs}" PARENT_SCOPE)
  set(${prefix}_LINK "${libraries}" PARENT_SCOPE)
endfunction()

# fvp_ros_find(<found_var>): the libraries and the header directories (FVP_ROS_INCLUDE_DIRS,
# FVP_ROS_LINK), or <found_var> FALSE with what is missing in FVP_ROS_MISSING.
function(fvp_ros_find found_var)
  _fvp_ros_find_set(FVP_ROS HEADERS ${FVP_ROS_HEADERS} LIBRARIES ${FVP_ROS_LIBRARIES})
  set(FVP_ROS_MISSING "${FVP_ROS_MISSING}" PARENT_SCOPE)
  set(FVP_ROS_INCLUDE_DIRS "${FVP_ROS_INCLUDE_DIRS}" PARENT_SCOPE)
  set(FVP_ROS_LINK "${FVP_ROS_LINK}" PARENT_SCOPE)
  if(FVP_ROS_MISSING)
    set(${found_var} FALSE PARENT_SCOPE)
  else()
    set(${found_var} TRUE PARENT_SCOPE)
  endif()
endfunction()

# The ROS nodes (ros/nodes, docs/ros.md) need roscpp, tf2_ros and actionlib besides the bag
# layer, and generate their action's C++ headers with Debian's genmsg/gencpp and actionlib_msgs'
# genaction.py (no catkin: see above).
set(FVP_ROS_NODE_LIBRARIES roscpp rosconsole xmlrpcpp tf2_ros actionlib)
set(FVP_ROS_NODE_HEADERS ros/ros.h actionlib/server/simple_action_server.h
    tf2_ros/transform_listener.h trajectory_msgs/JointTrajectory.h
    visualization_msgs/MarkerArray.h rosgraph_msgs/Clock.h sensor_msgs/JointState.h
    sensor_msgs/PointCloud2.h)

# fvp_ros_find_nodes(<found_var>): as fvp_ros_find, for the nodes' libraries, headers and message
# generators (FVP_ROS_NODE_INCLUDE_DIRS, FVP_ROS_NODE_LINK; what is missing in
# FVP_ROS_NODE_MISSING).
function(fvp_ros_find_nodes found_var)
  _fvp_ros_find_set(FVP_ROS_NODE HEADERS ${FVP_ROS_NODE_HEADERS}
                    LIBRARIES ${FVP_ROS_NODE_LIBRARIES})
  set(missing ${FVP_ROS_NODE_MISSING})
  # The generators run on Debian's interpreter, where python3-genmsg lives.
  find_program(FVP_ROS_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
  find_file(FVP_GENCPP gen_cpp.py PATHS /usr/lib/gencpp NO_DEFAULT_PATH)
  find_path(FVP_GENCPP_TEMPLATES msg.h.template PATHS /usr/share/gencpp NO_DEFAULT_PATH)
  find_file(FVP_GENACTION genaction.py PATHS /usr/lib/actionlib_msgs NO_DEFAULT_PATH)
  foreach(pkg std_msgs geometry_msgs actionlib_msgs)
    find_path(FVP_MSG_DIR_${pkg} NAMES Header.msg Point.msg GoalID.msg PATHS /usr/share/${pkg}/msg
              NO_DEFAULT_PATH)
    if(NOT FVP_MSG_DIR_${pkg})
      list(APPEND missing "${pkg} message definitions (ros-${pkg})")
    endif()
  endforeach()
  foreach(tool FVP_ROS_PYTHON FVP_GENCPP FVP_GENCPP_TEMPLATES FVP_GENACTION)
    if(NOT ${tool})
      list(APPEND missing ${tool})
    endif()
  endforeach()
  if(FVP_ROS_PYTHON AND NOT missing)
    execute_process(COMMAND ${FVP_ROS_PYTHON} -c "import genmsg, gencpp, em"
                    RESULT_VARIABLE import_failed OUTPUT_QUIET ERROR_QUIET)
    if(import_failed)
      list(APPEND missing "python3-genmsg/python3-gencpp")
    endif()
  endif()
  set(FVP_ROS_NODE_MISSING "${missing}" PARENT_SCOPE)
  set(FVP_ROS_NODE_INCLUDE_DIRS "${FVP_ROS_NODE_INCLUDE_DIRS}" PARENT_SCOPE)
  set(FVP_ROS_NODE_LINK "${FVP_ROS_NODE_LINK}" PARENT_SCOPE)
  if(missing)
    set(${found_var} FALSE PARENT_SCOPE)
  else()
    set(${found_var} TRUE PARENT_SCOPE)
  endif()
endfunction()

# fvp_ros_generate_messages(<target> PACKAGE <pkg> MSGS <files> ACTIONS <files>): an INTERFACE
# target whose include directory holds <pkg>/<Name>.h for every message and action message,
# generated at build time (a bad .msg fails the build).
function(fvp_ros_generate_messages target)
  cmake_parse_arguments(ARG "" "PACKAGE" "MSGS;ACTIONS" ${ARGN})
  set(gen ${CMAKE_CURRENT_BINARY_DIR}/generated)
  set(msg_dir ${gen}/msg)
  set(msgs)
  foreach(msg ${ARG_MSGS})
    get_filename_component(name ${msg} NAME)
    configure_file(${msg} ${msg_dir}/${name} COPYONLY)
    list(APPEND msgs ${msg_dir}/${name})
  endforeach()
  foreach(action ${ARG_ACTIONS})
    get_filename_component(base ${action} NAME_WE)
    set(outputs)
    foreach(part Action ActionGoal ActionResult ActionFeedback Goal Result Feedback)
      list(APPEND outputs ${msg_dir}/${base}${part}.msg)
    endforeach()
    add_custom_command(OUTPUT ${outputs}
      COMMAND ${FVP_ROS_PYTHON} ${FVP_GENACTION} -o ${msg_dir} ${action}
      DEPENDS ${action} VERBATIM)
    list(APPEND msgs ${outputs})
  endforeach()
  set(headers)
  foreach(msg ${msgs})
    get_filename_component(name ${msg} NAME_WE)
    set(header ${gen}/include/${ARG_PACKAGE}/${name}.h)
    add_custom_command(OUTPUT ${header}
      COMMAND ${FVP_ROS_PYTHON} ${FVP_GENCPP} -p ${ARG_PACKAGE} -o ${gen}/include/${ARG_PACKAGE}
              -e ${FVP_GENCPP_TEMPLATES} -I${ARG_PACKAGE}:${msg_dir}
              -Istd_msgs:${FVP_MSG_DIR_std_msgs} -Igeometry_msgs:${FVP_MSG_DIR_geometry_msgs}
              -Iactionlib_msgs:${FVP_MSG_DIR_actionlib_msgs} ${msg}
      DEPENDS ${msgs} VERBATIM)
    list(APPEND headers ${header})
  endforeach()
  add_custom_target(${target}_generate DEPENDS ${headers})
  add_library(${target} INTERFACE)
  add_dependencies(${target} ${target}_generate)
  target_include_directories(${target} SYSTEM INTERFACE ${gen}/include)
endfunction()
