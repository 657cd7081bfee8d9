// SGM's paths of one family (params.path_family): one work item per line, both ways. Body:
// fvp_stereo_aggregate_line in fvp_stereo.h, shared with the CPU reference.
#include "fvp_stereo.h"

__kernel void fvp_stereo_aggregate(const fvp_stereo_params p, const uint item_count,
                                   __global const uint* windows, __global const uint* costs,
                                   __global uint* sums) {
  const uint item = get_global_id(0);
  if (item >= item_count) return;
  fvp_stereo_aggregate_line(&p, windows, costs, item, sums);
}
