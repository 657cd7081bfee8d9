// ROI distance field (paper Eq. 1's d_i): exact Euclidean distance in voxels from every
// allocated voxel to the nearest known ROI voxel, capped at radius_vox. Three separable
// passes (p.axis = 0, 1, 2) of a windowed min-plus transform; body in fvp_map_kernels.h.
#include "fvp_map_kernels.h"

__kernel void fvp_roi_distance(const fvp_edt_params p, const uint item_count,
                               __global const int* brick_coords, __global const int* brick_table,
                               __global const float* roi, __global const uint* sq_in,
                               __global uint* sq_out, __global float* distance_vox) {
  const uint slot = get_global_id(0);
  if (slot >= item_count) return;
  fvp_roi_distance_slot(&p, slot, brick_coords, brick_table, roi, sq_in, sq_out, distance_vox);
}
