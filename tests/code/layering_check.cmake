# The layering check can fail (cmake/FvpLayering.cmake): the model in layering/ configures
# clean, and each way of linking a forbidden library fails with the path that does.
# cmake -DFVP_SOURCE_DIR=<source> -DWORK_DIR=<scratch> -P layering_check.cmake
cmake_minimum_required(VERSION 3.25)
set(cases
  "clean|"
  "public|session -> report"
  "private|session -> eval"
  "alias_genex|nbv -> report"
  "other_directory|core -> eval")
set(failures "")
foreach(entry IN LISTS cases)
  string(REPLACE "|" ";" entry "${entry}")
  list(GET entry 0 case)
  list(GET entry 1 expected)
  file(REMOVE_RECURSE ${WORK_DIR}/${case})
  execute_process(
    COMMAND ${CMAKE_COMMAND} -S ${FVP_SOURCE_DIR}/tests/code/layering -B ${WORK_DIR}/${case}
            -DCASE=${case} -DFVP_SOURCE_DIR=${FVP_SOURCE_DIR}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  # CMake wraps long messages: compare with the whitespace squeezed.
  string(REGEX REPLACE "[ \n]+" " " text "${out}${err}")
  if(expected STREQUAL "")
    if(NOT rc EQUAL 0)
      string(APPEND failures "\n${case}: the clean model failed to configure:\n${err}")
    endif()
  elseif(rc EQUAL 0)
    string(APPEND failures "\n${case}: configured, the violation ${expected} not caught")
  elseif(NOT text MATCHES "Layering.*${expected}")
    string(APPEND failures "\n${case}: failed, but without naming ${expected}:\n${err}")
  endif()
endforeach()
if(failures)
  message(FATAL_ERROR "layering check:${failures}")
endif()
message(STATUS "layering check: the clean model passes, 4 violations caught")
