#version 450
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "fvp_kernel.glsl"
#include "fvp_stereo.glsl"
// One family of SGM's paths: entry point of kernels/stereo_aggregate.cl's twin (fvp_stereo.glsl).

FVP_KERNEL_PARAMS(FvpStereoParams)
layout(std430, set = 0, binding = 0) readonly buffer Windows { uint windows[]; };
layout(std430, set = 0, binding = 1) readonly buffer Costs { uint costs[]; };
layout(std430, set = 0, binding = 2) buffer Sums { uint sums[]; };
#define FVP_HAS_WINDOWS
#define FVP_HAS_COSTS
#define FVP_HAS_SUMS
#include "fvp_stereo.glsl"

void main() {
  uint item = FVP_ITEM_INDEX;
  if (item >= FVP_ITEM_COUNT) return;
  fvp_stereo_aggregate_line(fvp_params.p, item);
}
