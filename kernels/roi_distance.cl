// ROI distance field (paper Eq. 1's d_i): exact Euclidean distance in voxels from every
// allocated voxel to the nearest known ROI voxel, capped at radius_vox. Three separable
// passes (p.axis = 0, 1, 2) of a windowed min-plus transform over the bricks near ROI (one
// work item per line of 8 voxels along the axis in work_bricks); body in fvp_map_kernels.h.
#include "fvp_map_kernels.h"

__kernel void fvp_roi_distance(const fvp_edt_params p, const uint item_count,
                               __global const int* brick_coords, __global const int* brick_table,
                               __global const float* roi, __global const uint* sq_in,
                               __global uint* sq_out, __global float* distance_vox,
                               __global const uint* work_bricks) {
  const uint i = get_global_id(0);
  if (i >= item_count) return;
  fvp_roi_distance_line(&p, i, brick_coords, brick_table, roi, sq_in, sq_out, distance_vox,
                        work_bricks);
}
