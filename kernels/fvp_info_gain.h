/* fvp_info_gain.h: the information-gain walk of one ray segment (paper Eq. 1-2) over the
 * planner's compact map snapshot. C subset shared by the C++ reference backend, the
 * planner's direct CPU path and the OpenCL kernel; shaders/info_gain.comp is the GLSL twin.
 *
 * The host splits each ray where it enters the Cluster Region sphere (in double precision,
 * once) and hands the kernel only end points: the walks themselves are the exact
 * fixed-point DDA of fvp_dda.h and the outputs are integers, so every backend returns
 * bit-identical results (a sphere test on the device would not be: sqrt and division are
 * not correctly rounded on every GPU).
 *
 * Snapshot layout (32-bit words, because GLSL has no portable 8- or 16-bit loads):
 * - fine codes: 2 bytes per fine voxel, voxel i in the low (i even) or high (i odd) half
 *   of word i / 2: FVP_GAIN_IN_REGION, FVP_GAIN_OCCUPIED and, for unknown voxels, Eq. 1's
 *   weight in units of 1 / FVP_GAIN_WEIGHT_SCALE;
 * - coarse occupancy: 1 byte per coarse voxel, voxel i in byte lane i % 4 of word i / 4,
 *   non-zero where occupied. */
#ifndef FVP_INFO_GAIN_H
#define FVP_INFO_GAIN_H

#include "fvp_dda.h"

#define FVP_GAIN_IN_REGION 0x8000u
#define FVP_GAIN_OCCUPIED 0x4000u
#define FVP_GAIN_WEIGHT_MASK 0x3FFFu
#define FVP_GAIN_WEIGHT_SCALE 8192u /* weight 1 */

/* One ray, split at the region: origin -> entry over the coarse map (only when
 * walk_coarse is set: the origin lies outside the region), entry -> end over the fine map. */
typedef struct fvp_gain_segment {
  float origin_m[4]; /* [3]: 1 = walk the coarse map to the entry first, 0 = do not */
  float entry_m[4];
  float end_m[4];
} fvp_gain_segment;

typedef struct fvp_gain_result {
  unsigned int weight_sum;    /* Eq. 1 weights of the unknown region voxels, scaled */
  unsigned int region_voxels; /* N_c: region voxels up to and including the stopping one */
  unsigned int voxel_steps;   /* coarse + fine voxels visited */
  unsigned int blocked;       /* 1: an occupied coarse voxel before the region */
} fvp_gain_result;

typedef struct fvp_gain_params {
  fvp_grid_params fine;
  fvp_grid_params coarse;
  unsigned int segment_count;
} fvp_gain_params;

FVP_FN unsigned int fvp_gain_fine_code(FVP_GLOBAL const unsigned int* fine_codes, int i) {
  return (fine_codes[i >> 1] >> ((unsigned int)(i & 1) * 16u)) & 0xFFFFu;
}

FVP_FN unsigned int fvp_gain_coarse_occupied(FVP_GLOBAL const unsigned int* coarse_occupied,
                                             int i) {
  return (coarse_occupied[i >> 2] >> ((unsigned int)(i & 3) * 8u)) & 0xFFu;
}

FVP_FN fvp_gain_result fvp_gain_walk(const fvp_gain_params* p, const float* origin_m,
                                     const float* entry_m, const float* end_m, int walk_coarse,
                                     FVP_GLOBAL const unsigned int* fine_codes,
                                     FVP_GLOBAL const unsigned int* coarse_occupied) {
  fvp_gain_result r;
  fvp_dda d;
  r.weight_sum = 0u;
  r.region_voxels = 0u;
  r.voxel_steps = 0u;
  r.blocked = 0u;
  /* Coarse map up to the region: the first occupied voxel blocks the view. */
  if (walk_coarse && fvp_dda_init(&d, &p->coarse, origin_m, entry_m) == 0) {
    int dim[3];
    dim[0] = p->coarse.dim_x;
    dim[1] = p->coarse.dim_y;
    dim[2] = p->coarse.dim_z;
    for (;;) {
      int axis;
      r.voxel_steps += 1u;
      if (fvp_gain_coarse_occupied(coarse_occupied,
                                   d.key[0] + dim[0] * (d.key[1] + dim[1] * d.key[2])) != 0u) {
        r.blocked = 1u;
        return r;
      }
      axis = fvp_dda_next_axis(&d);
      if (axis < 0) break;
      fvp_dda_advance(&d, axis);
      if (d.key[axis] < 0 || d.key[axis] >= dim[axis]) break;
    }
  }
  /* Fine map from the region's surface to the end point: region voxels count in N_c,
   * unknown ones add their weight, the first occupied one (counted) ends the walk. */
  if (fvp_dda_init(&d, &p->fine, entry_m, end_m) == 0) {
    int dim[3];
    dim[0] = p->fine.dim_x;
    dim[1] = p->fine.dim_y;
    dim[2] = p->fine.dim_z;
    for (;;) {
      int axis;
      unsigned int code;
      r.voxel_steps += 1u;
      code = fvp_gain_fine_code(fine_codes, d.key[0] + dim[0] * (d.key[1] + dim[1] * d.key[2]));
      if ((code & FVP_GAIN_IN_REGION) != 0u) {
        r.region_voxels += 1u;
        if ((code & FVP_GAIN_OCCUPIED) != 0u) return r;
        r.weight_sum += code & FVP_GAIN_WEIGHT_MASK;
      }
      axis = fvp_dda_next_axis(&d);
      if (axis < 0) break;
      fvp_dda_advance(&d, axis);
      if (d.key[axis] < 0 || d.key[axis] >= dim[axis]) break;
    }
  }
  return r;
}

#endif /* FVP_INFO_GAIN_H */
