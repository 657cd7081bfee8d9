// Projective TSDF integration of one view's ROI depth: one work item per voxel of the
// bricks to update. Body: fvp_tsdf_update_voxel in fvp_tsdf.h, shared with the CPU reference.
#include "fvp_tsdf.h"

__kernel void fvp_tsdf_integrate(const fvp_tsdf_params p, const uint item_count,
                                 __global const int* brick_coords,
                                 __global const uint* update_bricks, __global const float* depth_m,
                                 __global float* tsdf_distance, __global float* tsdf_weight) {
  const uint item = get_global_id(0);
  if (item >= item_count) return;
  fvp_tsdf_update_voxel(&p, brick_coords, update_bricks, item, depth_m, tsdf_distance, tsdf_weight);
}
