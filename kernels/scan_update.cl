// Scan integration, update pass: one work item per FVP_UPDATE_CHUNK slots. Body in
// fvp_map_kernels.h.
#include "fvp_map_kernels.h"

__kernel void fvp_scan_update(const fvp_update_params p, const uint item_count,
                              __global uint* marks, __global float* occupancy, __global float* roi,
                              __global uint* updated, __global uint* changed_bricks) {
  const uint i = get_global_id(0);
  if (i >= item_count) return;
  fvp_scan_update_item(&p, i, marks, occupancy, roi, updated, changed_bricks);
}
