# cmake -P script: writes a text file (the viewer's page, style and scripts, three.js) as a
# C++ raw string. Inputs: INPUT, OUTPUT, NAME.
file(READ ${INPUT} body)
if(body MATCHES "\\)fvp_text\"")
  message(FATAL_ERROR "${INPUT}: holds the raw-string delimiter )fvp_text\"")
endif()
file(WRITE ${OUTPUT}.tmp
  "// Generated from ${INPUT}; do not edit.\n"
  "#include <string_view>\n"
  "extern const std::string_view kText_${NAME};\n"
  "const std::string_view kText_${NAME} = R\"fvp_text(${body})fvp_text\";\n")
file(RENAME ${OUTPUT}.tmp ${OUTPUT})
