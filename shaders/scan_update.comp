#version 450
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "fvp_kernel.glsl"
#include "fvp_dda.glsl"
#include "fvp_map.glsl"
#include "fvp_map_kernels.glsl"
// Scan integration, update pass: entry point of kernels/scan_update.cl's twin.

FVP_KERNEL_PARAMS(FvpUpdateParams)
layout(std430, set = 0, binding = 0) buffer Marks { uint marks[]; };
layout(std430, set = 0, binding = 1) buffer Occupancy { float occupancy[]; };
layout(std430, set = 0, binding = 2) buffer Roi { float roi[]; };
layout(std430, set = 0, binding = 3) buffer Updated { uint updated[]; };
layout(std430, set = 0, binding = 4) buffer ChangedBricks { uint changed_bricks[]; };
#define FVP_HAS_MARKS
#define FVP_HAS_OCCUPANCY
#define FVP_HAS_ROI
#define FVP_HAS_UPDATED
#define FVP_HAS_CHANGED_BRICKS
#include "fvp_map.glsl"
#include "fvp_map_kernels.glsl"

void main() {
  uint i = FVP_ITEM_INDEX;
  if (i < FVP_ITEM_COUNT) fvp_scan_update_item(fvp_params.p, i);
}
