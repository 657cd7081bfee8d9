// Census signatures of the band's rows of both images: one work item per pixel. Body:
// fvp_stereo_census_pixel in fvp_stereo.h, shared with the CPU reference.
#include "fvp_stereo.h"

__kernel void fvp_stereo_census(const fvp_stereo_params p, const uint item_count,
                                __global const uint* grey, __global uint* census) {
  const uint item = get_global_id(0);
  if (item >= item_count) return;
  fvp_stereo_census_pixel(&p, grey, item, census);
}
