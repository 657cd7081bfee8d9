# cmake -P script: writes an OpenCL C source, with its local includes inlined (recursively;
# the headers' include guards drop repeats), as a C++ raw string.
# Inputs: INPUT, OUTPUT, NAME, INCLUDE_DIR.
file(READ ${INPUT} body)
foreach(depth RANGE 8)
  string(REGEX MATCHALL "#include \"[^\"]+\"" includes "${body}")
  if(NOT includes)
    break()
  endif()
  list(REMOVE_DUPLICATES includes)
  foreach(directive IN LISTS includes)
    string(REGEX REPLACE "#include \"([^\"]+)\"" "\\1" file_name "${directive}")
    set(header ${INCLUDE_DIR}/${file_name})
    if(NOT EXISTS ${header})
      message(FATAL_ERROR "${INPUT}: included file ${file_name} not found in ${INCLUDE_DIR}")
    endif()
    file(READ ${header} header_text)
    string(REPLACE "${directive}" "// ---- inlined ${file_name}\n${header_text}" body "${body}")
  endforeach()
endforeach()
if(body MATCHES "#include \"")
  message(FATAL_ERROR "${INPUT}: includes nested deeper than 8 levels")
endif()
file(WRITE ${OUTPUT}.tmp
  "// Generated from ${INPUT}; do not edit.\n"
  "extern const char kOpenClSource_${NAME}[];\n"
  "const char kOpenClSource_${NAME}[] = R\"fvp_cl(${body})fvp_cl\";\n")
file(RENAME ${OUTPUT}.tmp ${OUTPUT})
