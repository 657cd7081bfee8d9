# Install rules and the CMake package (docs/install.md): the public headers, the static
# libraries, the fvp program, and in <prefix>/lib/cmake/fvp the exported targets
# (fvpTargets.cmake, namespace fvp::), fvpConfig.cmake and fvpConfigVersion.cmake.
include(CMakePackageConfigHelpers)

# Every library in the link closure of the public ones: they are static, so a consumer's
# link line needs the private ones too. Exported as fvp::<name without the fvp_ prefix>; the
# same names are aliases in this build, for projects that add fvp as a subdirectory.
set(FVP_EXPORTED_LIBRARIES
  fvp_accel
  fvp_host_core fvp_host_perception fvp_host_map fvp_host_tsdf fvp_host_sizing fvp_host_eval
  fvp_host_session fvp_host_planner fvp_host_nbv fvp_host_report fvp_host_season
  fvp_robot_sim fvp_sim_pipeline fvp_robot fvp_robot_arm fvp_experiment_directory fvp_trial)
foreach(lib ${FVP_EXPORTED_LIBRARIES})
  string(REGEX REPLACE "^fvp_" "" name ${lib})
  set_target_properties(${lib} PROPERTIES EXPORT_NAME ${name})
  add_library(fvp::${name} ALIAS ${lib})
  # fvp_compile_options (warnings, -ffp-contract=off) stays in this build
  # ($<BUILD_INTERFACE:...> where linked), but objects built with sanitizers need the
  # sanitizer runtime wherever they are linked.
  if(FVP_SANITIZE)
    target_link_options(${lib} INTERFACE $<INSTALL_INTERFACE:-fsanitize=${FVP_SANITIZE}>)
  endif()
endforeach()
# The program, as an imported executable (like protobuf::protoc): fvp::fvp.
add_executable(fvp::fvp ALIAS fvp)

set(FVP_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/fvp)
install(TARGETS ${FVP_EXPORTED_LIBRARIES} fvp
  EXPORT fvpTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

# Public headers: include/ of each library (src/ holds the private ones), and the kernels'
# C headers that fvp/accel/kernel_types.h includes by their bare names.
install(
  DIRECTORY ${PROJECT_SOURCE_DIR}/accel/include/ ${PROJECT_SOURCE_DIR}/host/include/
            ${PROJECT_SOURCE_DIR}/robot/include/ ${PROJECT_SOURCE_DIR}/robot/sim/include/
            ${PROJECT_SOURCE_DIR}/trials/include/
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/kernels/
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/fvp/kernels
  FILES_MATCHING PATTERN "*.h")

# The documented YAML configs (keys and their defaults). Nothing reads them at run time:
# the defaults are compiled in; they are starting points for --world, --map-config etc.
install(
  FILES ${PROJECT_SOURCE_DIR}/host/config/map_default.yaml
        ${PROJECT_SOURCE_DIR}/host/config/planner_default.yaml
        ${PROJECT_SOURCE_DIR}/host/config/rvp_default.yaml
        ${PROJECT_SOURCE_DIR}/robot/config/arm_default.yaml
        ${PROJECT_SOURCE_DIR}/robot/sim/config/world_default.yaml
        ${PROJECT_SOURCE_DIR}/robot/sim/config/world_isolated.yaml
        ${PROJECT_SOURCE_DIR}/robot/sim/config/world_unoccluded.yaml
  DESTINATION ${CMAKE_INSTALL_DATADIR}/fvp/config)

install(EXPORT fvpTargets NAMESPACE fvp:: DESTINATION ${FVP_INSTALL_CMAKEDIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/fvpConfig.cmake.in
  ${PROJECT_BINARY_DIR}/fvpConfig.cmake
  INSTALL_DESTINATION ${FVP_INSTALL_CMAKEDIR})
# 0.x: a minor version may break the API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/fvpConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(
  FILES ${PROJECT_BINARY_DIR}/fvpConfig.cmake ${PROJECT_BINARY_DIR}/fvpConfigVersion.cmake
        ${PROJECT_SOURCE_DIR}/cmake/FvpOmpl.cmake
  DESTINATION ${FVP_INSTALL_CMAKEDIR})
