#version 450
// Batched voxel ray traversal: GLSL twin of kernels/ray_traverse.cl.
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "fvp_dda.glsl"

// Work-group size is chosen by the host from the device's limits (specialisation constant 0).
layout(local_size_x_id = 0) in;

layout(push_constant) uniform Params {
  FvpGridParams grid;
  float occupied_threshold;
  uint ray_count;
  uint first_ray;  // dispatches are chunked to stay within maxComputeWorkGroupCount
} params;

layout(std430, set = 0, binding = 0) readonly buffer Rays { FvpRay rays[]; };
layout(std430, set = 0, binding = 1) readonly buffer Occupancy { float occupancy[]; };
layout(std430, set = 0, binding = 2) readonly buffer Field { float field[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Results { FvpRayResult results[]; };

void main() {
  uint i = params.first_ray + gl_GlobalInvocationID.x;
  if (i >= params.ray_count) return;
  FvpGridParams g = params.grid;
  FvpRayResult r = FvpRayResult(0u, 0.0, -1, 0u);
  FvpDda d;
  r.status = fvp_dda_init(d, g, rays[i].origin_m.xyz, rays[i].end_m.xyz);
  if (r.status != 0u) {
    results[i] = r;
    return;
  }
  ivec3 dim = ivec3(g.dim_x, g.dim_y, g.dim_z);
  ivec3 stride = ivec3(1, g.dim_x, g.dim_x * g.dim_y);
  int index = d.key.x + stride.y * d.key.y + stride.z * d.key.z;
  for (;;) {
    r.steps += 1u;
    r.field_sum += field[index];
    if (occupancy[index] >= params.occupied_threshold) {
      r.status = FVP_RAY_HIT_OCCUPIED;
      r.stop_voxel = index;
      break;
    }
    int axis = fvp_dda_next_axis(d);
    if (axis < 0) {
      r.status = FVP_RAY_REACHED_END;
      r.stop_voxel = index;
      break;
    }
    fvp_dda_advance(d, axis);
    if (d.key[axis] < 0 || d.key[axis] >= dim[axis]) {
      r.status = FVP_RAY_LEFT_GRID;
      break;
    }
    index += d.step[axis] * stride[axis];
  }
  results[i] = r;
}
