#version 450
// ROI distance field pass: GLSL twin of kernels/roi_distance.cl.
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "fvp_dda.glsl"
#include "fvp_map.glsl"

layout(local_size_x_id = 0) in;

layout(push_constant) uniform Params {
  FvpEdtParams edt;
  int axis;
  uint first_item;
} params;

layout(std430, set = 0, binding = 0) readonly buffer BrickCoords { int brick_coords[]; };
layout(std430, set = 0, binding = 1) readonly buffer BrickTable { int brick_table[]; };
layout(std430, set = 0, binding = 2) readonly buffer Roi { float roi[]; };
layout(std430, set = 0, binding = 3) readonly buffer SqIn { uint sq_in[]; };
layout(std430, set = 0, binding = 4) writeonly buffer SqOut { uint sq_out[]; };
layout(std430, set = 0, binding = 5) writeonly buffer Distance { float distance_vox[]; };

void main() {
  uint slot = params.first_item + gl_GlobalInvocationID.x;
  FvpEdtParams p = params.edt;
  if (slot >= p.slot_count) return;
  uint brick = slot / 512u, in_brick = slot % 512u;
  ivec3 v = ivec3(brick_coords[3 * brick], brick_coords[3 * brick + 1], brick_coords[3 * brick + 2]) * 8 +
            ivec3(int(in_brick & 7u), int((in_brick >> 3) & 7u), int(in_brick >> 6));
  int axis = params.axis;
  uint best = FVP_EDT_FAR;
  for (int k = -p.radius_vox; k <= p.radius_vox; ++k) {
    ivec3 n = v;
    n[axis] += k;
    if (any(lessThan(n, ivec3(0))) || n.x >= p.map.grid.dim_x || n.y >= p.map.grid.dim_y ||
        n.z >= p.map.grid.dim_z)
      continue;
    int nb = brick_table[fvp_brick_of(p.map, n.x, n.y, n.z)];
    if (nb < 0) continue;
    int s = (nb & FVP_BRICK_INDEX_MASK) * FVP_BRICK_VOXELS + fvp_local_of(n.x, n.y, n.z);
    uint value;
    if (axis == 0) {
      float r = roi[s];
      if (fvp_is_nan(r) || !(r > 0.0)) continue;
      value = 0u;
    } else {
      value = sq_in[s];
      if (value == FVP_EDT_FAR) continue;
    }
    value += uint(k * k);
    best = min(best, value);
  }
  if (axis < 2) sq_out[slot] = best;
  else distance_vox[slot] = fvp_edt_distance_vox(best, p.radius_vox);
}
