# cmake -P script (the CTest case package.consumer): installs fvp's build tree into a staging
# prefix, moves it elsewhere (the package must not depend on where it was installed), checks
# that no installed CMake file or header names the source or build tree, then configures,
# builds and runs tests/package/consumer against the moved prefix.
#   FVP_BINARY_DIR, FVP_SOURCE_DIR, CONFIG  the fvp build
#   WORK_DIR              this test's own directory, emptied first (nothing else writes it)
#   CONSUMER_SOURCE_DIR   the consumer project
#   GENERATOR, C_COMPILER, CXX_COMPILER   what the consumer is built with
foreach(var FVP_BINARY_DIR FVP_SOURCE_DIR WORK_DIR CONSUMER_SOURCE_DIR GENERATOR)
  if(NOT ${var})
    message(FATAL_ERROR "install_and_consume.cmake: ${var} not set")
  endif()
endforeach()

function(run step)
  string(TIMESTAMP start "%s")
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  string(TIMESTAMP end "%s")
  math(EXPR seconds "${end} - ${start}")
  if(NOT rc EQUAL 0)
    message("${out}")
    message(FATAL_ERROR "${step} failed (${rc}): ${ARGN}")
  endif()
  message(STATUS "${step}: ok (${seconds} s)")
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
set(staging ${WORK_DIR}/staging)
set(prefix ${WORK_DIR}/prefix)
set(build ${WORK_DIR}/build)

set(config_args)
if(CONFIG)
  set(config_args --config ${CONFIG})
endif()
run("cmake --install" ${CMAKE_COMMAND} --install ${FVP_BINARY_DIR} --prefix ${staging}
    ${config_args})
file(RENAME ${staging} ${prefix})

# Relocatable: nothing installed points back at the trees fvp was built from.
file(GLOB_RECURSE installed_text LIST_DIRECTORIES false
     ${prefix}/*.cmake ${prefix}/*.h ${prefix}/*.yaml)
foreach(file ${installed_text})
  file(READ ${file} text)
  foreach(tree ${FVP_SOURCE_DIR} ${FVP_BINARY_DIR} ${staging})
    string(FIND "${text}" "${tree}" at)
    if(NOT at EQUAL -1)
      message(FATAL_ERROR "${file} names ${tree}: the package is not relocatable")
    endif()
  endforeach()
endforeach()
# <libdir>/cmake/fvp: lib, or lib/<multiarch> for the prefix /usr (GNUInstallDirs).
file(GLOB_RECURSE config_file ${prefix}/fvpConfig.cmake)
if(NOT config_file)
  message(FATAL_ERROR "not installed: fvpConfig.cmake")
endif()
get_filename_component(config_dir ${config_file} DIRECTORY)
foreach(required ${config_dir}/fvpConfigVersion.cmake ${config_dir}/fvpTargets.cmake
                 ${prefix}/include/fvp/accel/backend.h ${prefix}/include/fvp/kernels/fvp_dda.h
                 ${prefix}/bin/fvp)
  if(NOT EXISTS ${required})
    message(FATAL_ERROR "not installed: ${required}")
  endif()
endforeach()

set(build_type_args)
if(CONFIG)
  set(build_type_args -DCMAKE_BUILD_TYPE=${CONFIG})
endif()
# No package registry and no fvp from anywhere but the prefix.
run("configure the consumer" ${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR} -B ${build}
    -G ${GENERATOR} -DCMAKE_C_COMPILER=${C_COMPILER} -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
    ${build_type_args} -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
file(STRINGS ${build}/CMakeCache.txt fvp_dir REGEX "^fvp_DIR:")
if(NOT fvp_dir STREQUAL "fvp_DIR:PATH=${config_dir}")
  message(FATAL_ERROR "the consumer found another fvp: ${fvp_dir}")
endif()
# One job: a test beside others on a shared machine.
run("build the consumer" ${CMAKE_COMMAND} --build ${build} -j 1 ${config_args})

set(exe ${build}/fvp_consumer)
if(NOT EXISTS ${exe} AND CONFIG)
  set(exe ${build}/${CONFIG}/fvp_consumer)
endif()
run("run the consumer" ${exe})
message("${last_output}")
if(NOT last_output MATCHES "fvp_consumer: all checks passed")
  message(FATAL_ERROR "the consumer did not report success")
endif()

# The Python module from the prefix (PYTHON: the interpreter it was built for; unset when
# fvp was built without it): found there alone, imported, and asked something.
if(PYTHON)
  file(GLOB_RECURSE module ${prefix}/fvp.*.so)
  if(NOT module)
    message(FATAL_ERROR "not installed: the fvp Python module")
  endif()
  get_filename_component(module_dir ${module} DIRECTORY)
  # PYTHON_ENV: what a sanitizer build needs in the interpreter's environment (LD_PRELOAD),
  # entries separated by '|'.
  string(REPLACE "|" ";" PYTHON_ENV "${PYTHON_ENV}")
  run("import fvp from the prefix" ${CMAKE_COMMAND} -E env PYTHONPATH=${module_dir} ${PYTHON_ENV}
      ${PYTHON} -c "import fvp; assert fvp.__file__.startswith('${prefix}'), fvp.__file__; assert fvp.planners()[:2] == ['fvp', 'rvp']; assert fvp.backends()['cpu'] == 'available'; print('python: fvp from', fvp.__file__)")
  message("${last_output}")
endif()
