#version 450
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "fvp_kernel.glsl"
#include "fvp_stereo.glsl"
// Winners and the left-right check: entry point of kernels/stereo_select.cl's twin (fvp_stereo.glsl).

FVP_KERNEL_PARAMS(FvpStereoParams)
layout(std430, set = 0, binding = 0) readonly buffer Windows { uint windows[]; };
layout(std430, set = 0, binding = 1) readonly buffer Sums { uint sums[]; };
layout(std430, set = 0, binding = 2) buffer RightBest { uint right_best[]; };
layout(std430, set = 0, binding = 3) buffer Disparity { int disparity[]; };
#define FVP_HAS_WINDOWS
#define FVP_HAS_SUMS
#define FVP_HAS_RIGHT_BEST
#define FVP_HAS_DISPARITY
#include "fvp_stereo.glsl"

void main() {
  uint item = FVP_ITEM_INDEX;
  if (item >= FVP_ITEM_COUNT) return;
  fvp_stereo_select_row(fvp_params.p, item);
}
