#version 450
// Scan integration: GLSL twin of kernels/scan_integrate.cl. MODE 0 is the mark pass (one
// invocation per point), MODE 1 the update pass (one invocation per 64 slots).
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "fvp_dda.glsl"
#include "fvp_map.glsl"

layout(local_size_x_id = 0) in;
layout(constant_id = 1) const int MODE = 0;

layout(push_constant) uniform Params {
  FvpScanParams scan;
  FvpUpdateParams update;
  uint slot_count;
  int brick_count;
  uint first_item;
} params;

layout(std430, set = 0, binding = 0) readonly buffer Points { FvpScanPoint points[]; };
layout(std430, set = 0, binding = 1) readonly buffer BrickTable { int brick_table[]; };
layout(std430, set = 0, binding = 2) buffer Marks { uint marks[]; };
layout(std430, set = 0, binding = 3) buffer Missing { uint missing[]; };
layout(std430, set = 0, binding = 4) buffer Occupancy { float occupancy[]; };
layout(std430, set = 0, binding = 5) buffer Roi { float roi[]; };
layout(std430, set = 0, binding = 6) buffer Updated { uint updated[]; };

void mark(uint slot, uint bit) { atomicOr(marks[slot >> 2], bit << (8u * (slot & 3u))); }

void markPoint(uint i) {
  FvpScanParams p = params.scan;
  FvpScanPoint pt = points[i];
  FvpDda d;
  if (fvp_dda_init(d, p.map.grid, vec3(p.sensor_x_m, p.sensor_y_m, p.sensor_z_m),
                   vec3(pt.x_m, pt.y_m, pt.z_m)) != 0u)
    return;
  ivec3 dim = ivec3(p.map.grid.dim_x, p.map.grid.dim_y, p.map.grid.dim_z);
  ivec3 brick_stride = ivec3(1, p.map.bricks_x, p.map.bricks_x * p.map.bricks_y);
  const ivec3 local_stride = ivec3(1, 8, 64);
  int brick = fvp_brick_of(p.map, d.key.x, d.key.y, d.key.z);
  int entry = brick_table[brick];
  int local_index = fvp_local_of(d.key.x, d.key.y, d.key.z);
  for (;;) {
    int axis = fvp_dda_next_axis(d);
    bool last = axis < 0;
    bool mapped = p.map.use_region == 0 || (entry >= 0 && (entry & FVP_BRICK_INSIDE) != 0) ||
                  fvp_region_contains(p.map.region, d.key.x, d.key.y, d.key.z);
    if (mapped) {
      if (entry < 0) {
        missing[brick] = 1u;
        missing[params.brick_count] = 1u;
      } else {
        uint slot = uint((entry & FVP_BRICK_INDEX_MASK) * FVP_BRICK_VOXELS + local_index);
        if (!last) {
          mark(slot, FVP_MARK_FREE);
        } else if ((pt.flags & FVP_POINT_HIT) != 0u) {
          mark(slot, ((pt.flags & FVP_POINT_ROI) != 0u) ? (FVP_MARK_HIT | FVP_MARK_ROI) : FVP_MARK_HIT);
        }
      }
    }
    if (last) return;
    fvp_dda_advance(d, axis);
    if (d.key[axis] < 0 || d.key[axis] >= dim[axis]) return;
    if ((d.key[axis] & 7) == (d.step[axis] > 0 ? 0 : 7)) {
      brick += d.step[axis] * brick_stride[axis];
      entry = brick_table[brick];
      local_index -= d.step[axis] * 7 * local_stride[axis];
    } else {
      local_index += d.step[axis] * local_stride[axis];
    }
  }
}

void updateChunk(uint chunk) {
  FvpUpdateParams p = params.update;
  uint first = chunk * 64u;
  if (first >= p.slot_count) return;
  uint count = 0u;
  for (uint w = first >> 2; w < (first >> 2) + 16u; ++w) {
    uint word = marks[w];
    if (word == 0u) continue;
    for (uint lane = 0u; lane < 4u; ++lane) {
      uint m = (word >> (8u * lane)) & 0xffu;
      uint s = w * 4u + lane;
      if ((m & FVP_MARK_HIT) != 0u) {
        occupancy[s] = fvp_logodds_update(occupancy[s], p.hit_logodds, p.clamp_min_logodds, p.clamp_max_logodds);
        if (p.has_roi != 0)
          roi[s] = fvp_logodds_update(roi[s], (m & FVP_MARK_ROI) != 0u ? p.hit_logodds : p.miss_logodds,
                                      p.clamp_min_logodds, p.clamp_max_logodds);
        ++count;
      } else if ((m & FVP_MARK_FREE) != 0u) {
        occupancy[s] = fvp_logodds_update(occupancy[s], p.miss_logodds, p.clamp_min_logodds, p.clamp_max_logodds);
        ++count;
      }
    }
    marks[w] = 0u;
  }
  if (count != 0u) atomicAdd(updated[0], count);
}

void main() {
  uint i = params.first_item + gl_GlobalInvocationID.x;
  if (MODE == 0) {
    if (i < params.scan.point_count) markPoint(i);
  } else {
    updateChunk(i);
  }
}
