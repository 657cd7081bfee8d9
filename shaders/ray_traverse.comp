#version 450
// Batched voxel ray traversal: entry point of kernels/ray_traverse.cl's twin.
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "fvp_kernel.glsl"
#include "fvp_dda.glsl"

FVP_KERNEL_PARAMS(FvpTraverseParams)

layout(std430, set = 0, binding = 0) readonly buffer Rays { FvpRay rays[]; };
layout(std430, set = 0, binding = 1) readonly buffer Occupancy { float occupancy[]; };
layout(std430, set = 0, binding = 2) readonly buffer Field { float field[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Results { FvpRayResult results[]; };
#define FVP_HAS_DENSE_GRID
#include "fvp_dda.glsl"

void main() {
  uint i = FVP_ITEM_INDEX;
  if (i >= FVP_ITEM_COUNT) return;
  results[i] = fvp_traverse_ray(fvp_params.p.grid, fvp_params.p.occupied_threshold,
                                rays[i].origin_m.xyz, rays[i].end_m.xyz);
}
