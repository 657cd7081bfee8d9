// Each band pixel's two disparity windows from the guide and its 16 census costs. Body:
// fvp_stereo_cost_pixel in fvp_stereo.h, shared with the CPU reference.
#include "fvp_stereo.h"

__kernel void fvp_stereo_cost(const fvp_stereo_params p, const uint item_count,
                              __global const uint* census, __global const int* coarse_disparity,
                              __global uint* windows, __global uint* costs) {
  const uint item = get_global_id(0);
  if (item >= item_count) return;
  fvp_stereo_cost_pixel(&p, census, coarse_disparity, item, windows, costs);
}
