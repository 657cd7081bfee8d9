#version 450
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "fvp_kernel.glsl"
#include "fvp_stereo.glsl"
// Guided windows and census costs: entry point of kernels/stereo_cost.cl's twin (fvp_stereo.glsl).

FVP_KERNEL_PARAMS(FvpStereoParams)
layout(std430, set = 0, binding = 0) readonly buffer Census { uint census[]; };
layout(std430, set = 0, binding = 1) readonly buffer CoarseDisparity { int coarse_disparity[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Windows { uint windows[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Costs { uint costs[]; };
#define FVP_HAS_CENSUS
#define FVP_HAS_COARSE_DISPARITY
#define FVP_HAS_WINDOWS
#define FVP_HAS_COSTS
#include "fvp_stereo.glsl"

void main() {
  uint item = FVP_ITEM_INDEX;
  if (item >= FVP_ITEM_COUNT) return;
  fvp_stereo_cost_pixel(fvp_params.p, item);
}
