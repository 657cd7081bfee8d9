#version 450
// Projective TSDF integration: entry point of kernels/tsdf_integrate.cl's twin; the body
// fvp_tsdf_update_voxel is in fvp_tsdf.glsl.
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "fvp_kernel.glsl"
#include "fvp_dda.glsl"
#include "fvp_map.glsl"
#include "fvp_tsdf.glsl"

FVP_KERNEL_PARAMS(FvpTsdfParams)
layout(std430, set = 0, binding = 0) readonly buffer BrickCoords { int brick_coords[]; };
layout(std430, set = 0, binding = 1) readonly buffer UpdateBricks { uint update_bricks[]; };
layout(std430, set = 0, binding = 2) readonly buffer DepthM { float depth_m[]; };
layout(std430, set = 0, binding = 3) buffer TsdfDistance { float tsdf_distance[]; };
layout(std430, set = 0, binding = 4) buffer TsdfWeight { float tsdf_weight[]; };
#define FVP_HAS_TSDF_BUFFERS
#include "fvp_tsdf.glsl"

void main() {
  uint item = FVP_ITEM_INDEX;
  if (item >= FVP_ITEM_COUNT) return;
  fvp_tsdf_update_voxel(fvp_params.p, item);
}
