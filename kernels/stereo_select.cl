// Winners, uniqueness, subpixel and the left-right check: one work item per band row. Body:
// fvp_stereo_select_row in fvp_stereo.h, shared with the CPU reference.
#include "fvp_stereo.h"

__kernel void fvp_stereo_select(const fvp_stereo_params p, const uint item_count,
                                __global const uint* windows, __global const uint* sums,
                                __global uint* right_best, __global int* disparity) {
  const uint item = get_global_id(0);
  if (item >= item_count) return;
  fvp_stereo_select_row(&p, windows, sums, item, right_best, disparity);
}
