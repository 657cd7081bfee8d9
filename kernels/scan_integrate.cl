// Scan integration into bricked occupancy(+ROI) storage: a mark pass per point, then an
// update pass per 64 voxel slots. Bodies in fvp_map_kernels.h, shared with the CPU reference.
#include "fvp_map_kernels.h"

#define FVP_UPDATE_CHUNK 64u

// marks: three byte planes [free | hit | roi] of slot_count bytes each.
__kernel void fvp_scan_mark(const fvp_scan_params p, __global const fvp_scan_point* points,
                            __global const int* table, __global uchar* marks,
                            __global uint* missing, const uint slot_count, const int brick_count) {
  const uint i = get_global_id(0);
  if (i >= p.point_count) return;
  fvp_scan_mark_point(&p, points[i], table, marks, marks + slot_count, marks + 2 * slot_count,
                      missing, brick_count);
}

__kernel void fvp_scan_update(const fvp_update_params p, __global uchar* marks,
                              __global float* occupancy, __global float* roi,
                              __global uint* updated) {
  const uint first = get_global_id(0) * FVP_UPDATE_CHUNK;
  if (first >= p.slot_count) return;
  const uint n = fvp_scan_update_slots(&p, first, FVP_UPDATE_CHUNK, marks, marks + p.slot_count,
                                       marks + 2 * p.slot_count, occupancy, roi);
  if (n) atomic_add(updated, n);
}
