// Frontier extraction: ROI frontier (known ROI voxels next to unknown space) and
// exploration frontier (known free voxels next to unknown space, with a normal pointing
// away from the unknown). Entries are appended in any order; the host sorts them.
#include "fvp_map_kernels.h"

__kernel void fvp_extract_frontiers(const fvp_frontier_params p, const uint item_count,
                                    __global const int* brick_coords,
                                    __global const int* brick_table,
                                    __global const float* occupancy, __global const float* roi,
                                    __global fvp_frontier* frontiers, __global uint* count) {
  const uint slot = get_global_id(0);
  if (slot >= item_count) return;
  int x, y, z;
  fvp_slot_voxel(brick_coords, slot, &x, &y, &z);
  fvp_frontier_append(&p, x, y, z, brick_table, occupancy, roi, frontiers, count);
}
