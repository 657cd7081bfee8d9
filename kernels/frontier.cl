// Frontier extraction: ROI frontier (known ROI voxels next to unknown space) and
// exploration frontier (known free voxels next to unknown space, with a normal pointing
// away from the unknown). Entries are appended in any order; the host sorts them.
#include "fvp_map_kernels.h"

__kernel void fvp_extract_frontiers(const fvp_frontier_params p, __global const int* brick_coords,
                           __global const int* table, __global const float* occupancy,
                           __global const float* roi, __global fvp_frontier* out,
                           __global uint* count) {
  const uint slot = get_global_id(0);
  if (slot >= p.slot_count) return;
  int x, y, z, normal[3];
  fvp_slot_voxel(brick_coords, slot, &x, &y, &z);
  const uint flags = fvp_frontier_voxel(&p, x, y, z, table, occupancy, roi, normal);
  if (!flags) return;
  const uint index = atomic_inc(count);
  if (index < p.capacity) {
    fvp_frontier f;
    f.x = x;
    f.y = y;
    f.z = z;
    f.flags = flags;
    f.normal_x = normal[0];
    f.normal_y = normal[1];
    f.normal_z = normal[2];
    f.pad = 0;
    out[index] = f;
  }
}
