// Scan integration, update pass: one work item per FVP_UPDATE_CHUNK slots. Body in
// fvp_map_kernels.h.
#include "fvp_map_kernels.h"

__kernel void fvp_scan_update(const fvp_update_params p, const uint item_count,
                              __global uint* marks, __global float* occupancy, __global float* roi,
                              __global uint* updated) {
  const uint i = get_global_id(0);
  if (i >= item_count) return;
  const uint n = fvp_scan_update_chunk(&p, i * FVP_UPDATE_CHUNK, marks, occupancy, roi);
  if (n) atomic_add(updated, n);
}
