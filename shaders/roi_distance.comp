#version 450
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "fvp_kernel.glsl"
#include "fvp_dda.glsl"
#include "fvp_map.glsl"
#include "fvp_map_kernels.glsl"
// ROI distance field pass: entry point of kernels/roi_distance.cl's twin.

FVP_KERNEL_PARAMS(FvpEdtParams)
layout(std430, set = 0, binding = 0) readonly buffer BrickCoords { int brick_coords[]; };
layout(std430, set = 0, binding = 1) readonly buffer BrickTable { int brick_table[]; };
layout(std430, set = 0, binding = 2) readonly buffer Roi { float roi[]; };
layout(std430, set = 0, binding = 3) readonly buffer SqIn { uint sq_in[]; };
layout(std430, set = 0, binding = 4) writeonly buffer SqOut { uint sq_out[]; };
layout(std430, set = 0, binding = 5) writeonly buffer Distance { float distance_vox[]; };
layout(std430, set = 0, binding = 6) readonly buffer WorkBricks { uint work_bricks[]; };
#define FVP_HAS_BRICK_COORDS
#define FVP_HAS_BRICK_TABLE
#define FVP_HAS_ROI
#define FVP_HAS_SQ_IN
#define FVP_HAS_SQ_OUT
#define FVP_HAS_DISTANCE_VOX
#include "fvp_map.glsl"
#include "fvp_map_kernels.glsl"

void main() {
  uint i = FVP_ITEM_INDEX;
  if (i >= FVP_ITEM_COUNT) return;
  fvp_roi_distance_line(fvp_params.p, i);
}
