// ROI distance field (paper Eq. 1's d_i): exact Euclidean distance in voxels from every
// allocated voxel to the nearest known ROI voxel, capped at radius_vox. Three separable
// passes (x, y, z) of a windowed min-plus transform; body in fvp_map_kernels.h.
#include "fvp_map_kernels.h"

__kernel void fvp_roi_distance_pass(const fvp_edt_params p, const int axis,
                                    __global const int* brick_coords, __global const int* table,
                                    __global const float* roi, __global const uint* sq_in,
                                    __global uint* sq_out, __global float* distance_vox) {
  const uint slot = get_global_id(0);
  if (slot >= p.slot_count) return;
  int x, y, z;
  fvp_slot_voxel(brick_coords, slot, &x, &y, &z);
  const uint best = fvp_edt_pass_voxel(&p, axis, x, y, z, table, roi, sq_in);
  if (axis < 2) sq_out[slot] = best;
  else distance_vox[slot] = fvp_edt_distance_vox(best, p.radius_vox);
}
