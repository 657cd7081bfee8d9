#version 450
// Frontier extraction: GLSL twin of kernels/frontier.cl.
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "fvp_dda.glsl"
#include "fvp_map.glsl"

layout(local_size_x_id = 0) in;

layout(push_constant) uniform Params {
  FvpFrontierParams frontier;
  uint first_item;
} params;

layout(std430, set = 0, binding = 0) readonly buffer BrickCoords { int brick_coords[]; };
layout(std430, set = 0, binding = 1) readonly buffer BrickTable { int brick_table[]; };
layout(std430, set = 0, binding = 2) readonly buffer Occupancy { float occupancy[]; };
layout(std430, set = 0, binding = 3) readonly buffer Roi { float roi[]; };
layout(std430, set = 0, binding = 4) writeonly buffer Out { FvpFrontier frontiers[]; };
layout(std430, set = 0, binding = 5) buffer Count { uint count[]; };

bool unknownAt(FvpBrickedGrid m, ivec3 n) {
  int nb = brick_table[fvp_brick_of(m, n.x, n.y, n.z)];
  if (nb < 0) return true;
  return fvp_is_nan(occupancy[(nb & FVP_BRICK_INDEX_MASK) * FVP_BRICK_VOXELS + fvp_local_of(n.x, n.y, n.z)]);
}

void main() {
  uint slot = params.first_item + gl_GlobalInvocationID.x;
  FvpFrontierParams p = params.frontier;
  if (slot >= p.slot_count) return;
  uint brick = slot / 512u, in_brick = slot % 512u;
  ivec3 v = ivec3(brick_coords[3 * brick], brick_coords[3 * brick + 1], brick_coords[3 * brick + 2]) * 8 +
            ivec3(int(in_brick & 7u), int((in_brick >> 3) & 7u), int(in_brick >> 6));
  if (!fvp_in_map(p.map, v.x, v.y, v.z)) return;
  float occ = occupancy[slot];
  if (fvp_is_nan(occ)) return;
  float roi_value = roi[slot];
  bool is_roi = !fvp_is_nan(roi_value) && roi_value > 0.0;
  bool is_free = !(occ > p.occupied_logodds);
  if (!is_roi && !is_free) return;
  ivec3 normal = ivec3(0);
  bool face_unknown = false;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        ivec3 d = ivec3(dx, dy, dz);
        int manhattan = int(dx != 0) + int(dy != 0) + int(dz != 0);
        ivec3 n = v + d;
        if (manhattan == 0 || !fvp_in_map(p.map, n.x, n.y, n.z)) continue;
        if (!unknownAt(p.map, n)) continue;
        if (manhattan == 1) face_unknown = true;
        normal -= d;
      }
  if (!face_unknown) return;
  uint flags = (is_roi ? FVP_FRONTIER_ROI : 0u) | (is_free ? FVP_FRONTIER_EXPLORE : 0u);
  uint index = atomicAdd(count[0], 1u);
  if (index < p.capacity)
    frontiers[index] = FvpFrontier(v.x, v.y, v.z, flags, normal.x, normal.y, normal.z, 0);
}
