// Scan integration, mark pass: one work item per point. Body in fvp_map_kernels.h.
#include "fvp_map_kernels.h"

__kernel void fvp_scan_mark(const fvp_scan_params p, const uint item_count,
                            __global const fvp_scan_point* points, __global const int* brick_table,
                            __global uint* marks, __global uint* missing) {
  const uint i = get_global_id(0);
  if (i >= item_count) return;
  fvp_scan_mark_point(&p, points[i], brick_table, marks, missing);
}
