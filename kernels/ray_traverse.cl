// Batched voxel ray traversal over a dense grid: one work item per ray. Body:
// fvp_traverse_ray in fvp_dda.h, shared with the CPU reference.
#include "fvp_dda.h"

__kernel void fvp_ray_traverse(const fvp_traverse_params p, const uint item_count,
                               __global const fvp_ray* rays, __global const float* occupancy,
                               __global const float* field, __global fvp_ray_result* results) {
  const uint i = get_global_id(0);
  if (i >= item_count) return;
  const fvp_ray ray = rays[i];  // private copy: the walk takes private pointers
  results[i] =
      fvp_traverse_ray(&p.grid, p.occupied_threshold, ray.origin_m, ray.end_m, occupancy, field);
}
