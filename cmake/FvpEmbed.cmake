# Build-time embedding of compute kernels into the library, so nothing is read from
# disk at run time and a broken shader fails the build.

set(FVP_EMBED_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/EmbedOpenClSource.cmake)

# fvp_embed_opencl(<out_var> <kernel.cl>...): each kernel becomes a C++ source defining
#   extern const char kOpenClSource_<name>[];
# with its local `#include "x.h"` lines (from kernels/) inlined.
function(fvp_embed_opencl out_var)
  set(generated)
  file(GLOB headers ${PROJECT_SOURCE_DIR}/kernels/*.h)
  foreach(cl ${ARGN})
    get_filename_component(name ${cl} NAME_WE)
    set(out ${CMAKE_CURRENT_BINARY_DIR}/embedded/opencl_${name}.cpp)
    add_custom_command(
      OUTPUT ${out}
      COMMAND ${CMAKE_COMMAND} -DINPUT=${cl} -DOUTPUT=${out} -DNAME=${name}
              -DINCLUDE_DIR=${PROJECT_SOURCE_DIR}/kernels -P ${FVP_EMBED_SCRIPT}
      DEPENDS ${cl} ${headers} ${FVP_EMBED_SCRIPT}
      COMMENT "Embedding OpenCL kernel ${name}")
    list(APPEND generated ${out})
  endforeach()
  set(${out_var} ${generated} PARENT_SCOPE)
endfunction()

# fvp_compile_shaders(<out_var> <shader.comp>...): each shader is compiled to SPIR-V by
# glslangValidator and becomes a header declaring `const uint32_t kSpirv_<name>[]`.
function(fvp_compile_shaders out_var)
  set(generated)
  file(GLOB includes ${PROJECT_SOURCE_DIR}/shaders/*.glsl)
  foreach(comp ${ARGN})
    get_filename_component(name ${comp} NAME_WE)
    set(out ${CMAKE_CURRENT_BINARY_DIR}/embedded/spirv_${name}.h)
    add_custom_command(
      OUTPUT ${out}
      COMMAND Vulkan::glslangValidator -V --target-env vulkan1.1
              -I${PROJECT_SOURCE_DIR}/shaders --vn kSpirv_${name} -o ${out} ${comp}
      DEPENDS ${comp} ${includes}
      COMMENT "Compiling compute shader ${name} to SPIR-V")
    list(APPEND generated ${out})
  endforeach()
  set(${out_var} ${generated} PARENT_SCOPE)
endfunction()
