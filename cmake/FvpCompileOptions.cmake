# Warnings and sanitizers shared by every fvp target.
add_library(fvp_compile_options INTERFACE)
target_compile_options(fvp_compile_options INTERFACE
  -Wall -Wextra -Wpedantic -Wno-unused-parameter
  # Kernels and their CPU twins must round identically: no fused multiply-add contraction.
  -ffp-contract=off)
if(FVP_SANITIZE)
  target_compile_options(fvp_compile_options INTERFACE
    -fsanitize=${FVP_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  target_link_options(fvp_compile_options INTERFACE -fsanitize=${FVP_SANITIZE})
endif()
