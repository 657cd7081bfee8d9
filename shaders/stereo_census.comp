#version 450
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "fvp_kernel.glsl"
#include "fvp_stereo.glsl"
// Census signatures: entry point of kernels/stereo_census.cl's twin (fvp_stereo.glsl).

FVP_KERNEL_PARAMS(FvpStereoParams)
layout(std430, set = 0, binding = 0) readonly buffer Grey { uint grey[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Census { uint census[]; };
#define FVP_HAS_GREY
#define FVP_HAS_CENSUS
#include "fvp_stereo.glsl"

void main() {
  uint item = FVP_ITEM_INDEX;
  if (item >= FVP_ITEM_COUNT) return;
  fvp_stereo_census_pixel(fvp_params.p, item);
}
