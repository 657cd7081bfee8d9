# The layering rule (docs/design.md, "Layers"), checked when the build is configured: a
# robot-facing library, one a robot's program links, reaches no library of the layers above it
# (the reporting layer with three.js and the viewer, ground-truth scoring, the simulator and
# the trials), neither directly nor through another library. Checked on the link graph, not
# on a list of dependencies kept by hand, so a link added anywhere is seen.
# tests/code/layering/ proves that a violation fails the configuration.

# The target an item of LINK_LIBRARIES / INTERFACE_LINK_LIBRARIES names, or "" for a flag, a
# file, a target of the installed tree only, or the marker CMake puts around items that
# target_link_libraries added from another directory ("::@(...)", "::@").
function(_fvp_link_item_target out item)
  set(name "${item}")
  # $<LINK_ONLY:x> (a static library's private dependency) and $<BUILD_INTERFACE:x> link x in
  # this build; $<INSTALL_INTERFACE:x> does not.
  if(name MATCHES "^\\$<INSTALL_INTERFACE:")
    set(name "")
  endif()
  while(name MATCHES "^\\$<(LINK_ONLY|BUILD_INTERFACE):(.*)>$")
    set(name "${CMAKE_MATCH_2}")
  endwhile()
  if(name MATCHES "^::@" OR NOT TARGET "${name}")
    set(name "")
  else()
    get_target_property(aliased "${name}" ALIASED_TARGET)
    if(aliased)
      set(name "${aliased}")
    endif()
  endif()
  set(${out} "${name}" PARENT_SCOPE)
endfunction()

# The first link path ("a -> b -> c", breadth first: a shortest one) from root to a target in
# the list `forbidden`, into out; "" when there is none. Imported targets (the Debian
# packages) are not walked: they cannot link a library of this build.
function(fvp_forbidden_link_path out root forbidden)
  set(queue "${root}")
  set(seen "${root}")
  while(queue)
    list(POP_FRONT queue path)
    string(REGEX REPLACE "^.* -> " "" target "${path}")
    get_target_property(imported "${target}" IMPORTED)
    if(imported)
      continue()
    endif()
    get_target_property(direct "${target}" LINK_LIBRARIES)
    get_target_property(interface "${target}" INTERFACE_LINK_LIBRARIES)
    foreach(item IN LISTS direct interface)
      _fvp_link_item_target(next "${item}")
      if(NOT next OR next IN_LIST seen)
        continue()
      endif()
      list(APPEND seen "${next}")
      if(next IN_LIST forbidden)
        set(${out} "${path} -> ${next}" PARENT_SCOPE)
        return()
      endif()
      list(APPEND queue "${path} -> ${next}")
    endforeach()
  endwhile()
  set(${out} "" PARENT_SCOPE)
endfunction()

# FATAL_ERROR naming each path by which a target of ROBOT_FACING links one of FORBIDDEN.
function(fvp_check_layering)
  cmake_parse_arguments(arg "" "" "ROBOT_FACING;FORBIDDEN" ${ARGN})
  set(violations "")
  foreach(target IN LISTS arg_ROBOT_FACING)
    if(NOT TARGET "${target}")
      message(FATAL_ERROR "fvp_check_layering: no target ${target} (renamed? update the list)")
    endif()
    fvp_forbidden_link_path(path "${target}" "${arg_FORBIDDEN}")
    if(path)
      string(APPEND violations "\n  ${path}")
    endif()
  endforeach()
  if(violations)
    message(FATAL_ERROR
      "Layering (docs/design.md, \"Layers\"): a robot-facing library links a library of the "
      "reporting, scoring or simulation layers:${violations}\n"
      "Move the code that needs it into that layer (e.g. fvp_host_report) instead.")
  endif()
endfunction()
