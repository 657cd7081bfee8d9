# fvp::ompl: OMPL as an imported target, after find_package(ompl). Debian's omplConfig.cmake
# defines no target, and its OMPL_LIBRARIES lists Boost's and ODE's development libraries
# after libompl, which libompl-dev does not install; libompl.so carries those dependencies
# itself, so the target is that first library alone. Included by the build and by the
# installed fvpConfig.cmake (fvp::robot links it), so both resolve OMPL the same way.
if(NOT TARGET fvp::ompl)
  list(GET OMPL_LIBRARIES 0 _fvp_ompl_library)
  add_library(fvp::ompl UNKNOWN IMPORTED GLOBAL)
  set_target_properties(fvp::ompl PROPERTIES
    IMPORTED_LOCATION "${_fvp_ompl_library}"
    INTERFACE_INCLUDE_DIRECTORIES "${OMPL_INCLUDE_DIRS}")
  unset(_fvp_ompl_library)
endif()
