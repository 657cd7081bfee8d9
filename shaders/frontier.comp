#version 450
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "fvp_kernel.glsl"
#include "fvp_dda.glsl"
#include "fvp_map.glsl"
#include "fvp_map_kernels.glsl"
// Frontier extraction: entry point of kernels/frontier.cl's twin.

FVP_KERNEL_PARAMS(FvpFrontierParams)
layout(std430, set = 0, binding = 0) readonly buffer BrickCoords { int brick_coords[]; };
layout(std430, set = 0, binding = 1) readonly buffer BrickTable { int brick_table[]; };
layout(std430, set = 0, binding = 2) readonly buffer Occupancy { float occupancy[]; };
layout(std430, set = 0, binding = 3) readonly buffer Roi { float roi[]; };
layout(std430, set = 0, binding = 4) writeonly buffer Frontiers { FvpFrontier frontiers[]; };
layout(std430, set = 0, binding = 5) buffer Count { uint count[]; };
#define FVP_HAS_BRICK_COORDS
#define FVP_HAS_BRICK_TABLE
#define FVP_HAS_OCCUPANCY
#define FVP_HAS_ROI
#define FVP_HAS_FRONTIERS
#define FVP_HAS_COUNT
#include "fvp_map.glsl"
#include "fvp_map_kernels.glsl"

void main() {
  uint slot = FVP_ITEM_INDEX;
  if (slot >= FVP_ITEM_COUNT) return;
  int x, y, z;
  fvp_slot_voxel(slot, x, y, z);
  fvp_frontier_append(fvp_params.p, x, y, z);
}
