// Information gain of ray segments over the planner's map snapshot (paper Eq. 1-2): one
// work item per segment. Body: fvp_gain_walk in fvp_info_gain.h, shared with the CPU
// reference.
#include "fvp_info_gain.h"

__kernel void fvp_info_gain(const fvp_gain_params p, const uint item_count,
                            __global const fvp_gain_segment* segments,
                            __global const uint* fine_codes, __global const uint* coarse_occupied,
                            __global fvp_gain_result* results) {
  const uint i = get_global_id(0);
  if (i >= item_count) return;
  const fvp_gain_segment s = segments[i];  // private copy: the walk takes private pointers
  results[i] = fvp_gain_walk(&p, s.origin_m, s.entry_m, s.end_m, s.origin_m[3] != 0.0f, fine_codes,
                             coarse_occupied);
}
