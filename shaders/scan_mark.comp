#version 450
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "fvp_kernel.glsl"
#include "fvp_dda.glsl"
#include "fvp_map.glsl"
#include "fvp_map_kernels.glsl"
// Scan integration, mark pass: entry point of kernels/scan_mark.cl's twin.

FVP_KERNEL_PARAMS(FvpScanParams)
layout(std430, set = 0, binding = 0) readonly buffer Points { FvpScanPoint points[]; };
layout(std430, set = 0, binding = 1) readonly buffer BrickTable { int brick_table[]; };
layout(std430, set = 0, binding = 2) buffer Marks { uint marks[]; };
layout(std430, set = 0, binding = 3) buffer Missing { uint missing[]; };
#define FVP_HAS_BRICK_TABLE
#define FVP_HAS_MARKS
#define FVP_HAS_MISSING
#include "fvp_map.glsl"
#include "fvp_map_kernels.glsl"

void main() {
  uint i = FVP_ITEM_INDEX;
  if (i < FVP_ITEM_COUNT) fvp_scan_mark_point(fvp_params.p, points[i]);
}
