/* fvp_dda.h: exact 3-D voxel traversal (Amanatides & Woo) over a dense grid.
 *
 * One C-subset source shared by the C++ reference backend (accel/src/cpu_backend.cpp)
 * and the OpenCL kernels (kernels/ *.cl, where the build inlines it). The GLSL twin
 * is shaders/fvp_dda.glsl; tests check all three agree exactly.
 *
 * Why integer fixed point: floating-point DDAs diverge between devices at near-ties
 * (division accuracy differs, FMA contraction differs), so cross-backend results
 * would not be exact. Here end points are quantised once to 1/65536 voxel with a
 * sub and a mul (correctly rounded on every OpenCL and Vulkan device), and the walk
 * itself uses only 64-bit integer adds and compares: every backend visits the same
 * voxels in the same order.
 *
 * Voxel (i, j, k) covers [origin + i*voxel_size, origin + (i+1)*voxel_size) on each
 * axis, as OctoMap's keys do on a grid aligned to them. The walk visits the origin
 * voxel, then one voxel per boundary crossing, in order of the crossing's ray
 * parameter; crossings at the same parameter step z before y before x (OctoMap's
 * computeRayKeys order). It ends in the end point's voxel, which it includes
 * (computeRayKeys excludes it). A ray starting outside the grid enters where the
 * same walk from its origin would: only in-grid voxels are visited.
 */
#ifndef FVP_DDA_H
#define FVP_DDA_H

#ifdef __OPENCL_VERSION__
#pragma OPENCL FP_CONTRACT OFF
typedef long fvp_i64;
#define FVP_FN static inline
#define FVP_GLOBAL __global
#define FVP_FLOORF floor
#else
#include <math.h>
#include <stdint.h>
typedef int64_t fvp_i64;
#define FVP_FN static inline
#define FVP_GLOBAL
#define FVP_FLOORF floorf
#endif

/* Fixed point: 16 fractional bits per voxel. */
#define FVP_DDA_FRACTION_BITS 16
#define FVP_DDA_ONE ((fvp_i64)1 << FVP_DDA_FRACTION_BITS)
/* End points must lie within +-8192 voxels of the grid origin: keeps every product
 * of the walk below 2^61. Farther points make the ray invalid, never wrong. */
#define FVP_DDA_MAX_ABS_FIXED 536870912.0f /* 8192 * 65536 = 2^29 */

/* Outcome of a ray (fvp_ray_result.status). */
#define FVP_RAY_REACHED_END 0u  /* walked to the end voxel */
#define FVP_RAY_HIT_OCCUPIED 1u /* stopped at a voxel at or above the threshold */
#define FVP_RAY_LEFT_GRID 2u    /* left the grid, or never entered it */
#define FVP_RAY_INVALID 3u      /* NaN / infinite / out-of-range end point */

/* Dense grid geometry. x varies fastest: index = x + dim_x * (y + dim_y * z). */
typedef struct fvp_grid_params {
  int dim_x, dim_y, dim_z;
  float origin_x_m, origin_y_m, origin_z_m; /* world corner of voxel (0, 0, 0) */
  float voxel_size_m;
  float fixed_per_m; /* FVP_DDA_ONE / voxel_size_m, rounded once on the host */
} fvp_grid_params;

/* One ray: world end points (the fourth component is padding for GPU layouts). */
typedef struct fvp_ray {
  float origin_m[4];
  float end_m[4];
} fvp_ray;

typedef struct fvp_ray_result {
  unsigned int steps;  /* in-grid voxels visited, the stopping voxel included */
  float field_sum;     /* sum of the per-voxel field over the visited voxels */
  int stop_voxel;      /* linear index of the stopping voxel, -1 if none */
  unsigned int status; /* FVP_RAY_* */
} fvp_ray_result;

typedef struct fvp_traverse_params {
  fvp_grid_params grid;
  float occupied_threshold; /* stop at the first voxel whose value is >= this */
  unsigned int ray_count;
} fvp_traverse_params;

/* Walk state. "remaining" counts the boundary crossings left on each axis before the
 * end voxel; cross_ab = dist_a * len_b - dist_b * len_a is negative exactly when
 * the next a-crossing comes before the next b-crossing. */
typedef struct fvp_dda {
  int key[3];
  int step[3];
  int remaining[3];
  fvp_i64 step_len[3]; /* FVP_DDA_ONE * |end - origin| per axis, fixed point */
  fvp_i64 cross_xy, cross_xz, cross_yz;
} fvp_dda;

FVP_FN fvp_i64 fvp_floor_div_one(fvp_i64 v) {
  /* floor(v / FVP_DDA_ONE) without relying on the sign behaviour of >> */
  return v >= 0 ? v / FVP_DDA_ONE : -((-v + FVP_DDA_ONE - 1) / FVP_DDA_ONE);
}

/* World coordinate -> fixed-point grid coordinate; 0 if NaN, infinite or too far. */
FVP_FN int fvp_dda_quantize(float p_m, float origin_m, float fixed_per_m, fvp_i64* out) {
  float q = (p_m - origin_m) * fixed_per_m;
  if (!(q > -FVP_DDA_MAX_ABS_FIXED && q < FVP_DDA_MAX_ABS_FIXED)) return 0;
  *out = (fvp_i64)FVP_FLOORF(q);
  return 1;
}

/* Number of crossings k >= 0 on an axis (first at dist, then every FVP_DDA_ONE, axis
 * length len) that come before the event at parameter num / den; ties count as before
 * when tie_before is set. All arguments non-negative, den > 0. */
FVP_FN fvp_i64 fvp_dda_crossings_before(fvp_i64 dist, fvp_i64 len, fvp_i64 num, fvp_i64 den,
                                        int tie_before) {
  fvp_i64 r = num * len - dist * den;
  fvp_i64 unit = FVP_DDA_ONE * den;
  if (tie_before) return r >= 0 ? r / unit + 1 : 0;
  return r > 0 ? (r - 1) / unit + 1 : 0;
}

FVP_FN void fvp_dda_set_cross_terms(fvp_dda* d, const fvp_i64* dist) {
  fvp_i64 lx = d->step_len[0] / FVP_DDA_ONE, ly = d->step_len[1] / FVP_DDA_ONE,
          lz = d->step_len[2] / FVP_DDA_ONE;
  d->cross_xy = dist[0] * ly - dist[1] * lx;
  d->cross_xz = dist[0] * lz - dist[2] * lx;
  d->cross_yz = dist[1] * lz - dist[2] * ly;
}

/* Prepares the walk of one ray. Returns 0 when d holds the first in-grid voxel,
 * FVP_RAY_LEFT_GRID when the segment never enters the grid, FVP_RAY_INVALID for
 * unusable end points. With skip_outside = 0 the walk starts at the origin voxel
 * even outside the grid (the brute-force reference the tests compare against). */
FVP_FN unsigned int fvp_dda_init_ex(fvp_dda* d, const fvp_grid_params* g, const float* o_m,
                                    const float* e_m, int skip_outside) {
  fvp_i64 o[3], e[3], dist[3], len[3];
  float origin_m[3];
  int dim[3];
  int a;
  origin_m[0] = g->origin_x_m;
  origin_m[1] = g->origin_y_m;
  origin_m[2] = g->origin_z_m;
  dim[0] = g->dim_x;
  dim[1] = g->dim_y;
  dim[2] = g->dim_z;
  for (a = 0; a < 3; ++a) {
    if (!fvp_dda_quantize(o_m[a], origin_m[a], g->fixed_per_m, &o[a]) ||
        !fvp_dda_quantize(e_m[a], origin_m[a], g->fixed_per_m, &e[a]))
      return FVP_RAY_INVALID;
  }
  for (a = 0; a < 3; ++a) {
    fvp_i64 k0 = fvp_floor_div_one(o[a]);
    fvp_i64 k1 = fvp_floor_div_one(e[a]);
    d->key[a] = (int)k0;
    if (e[a] > o[a]) {
      d->step[a] = 1;
      len[a] = e[a] - o[a];
      dist[a] = (k0 + 1) * FVP_DDA_ONE - o[a]; /* in (0, ONE] */
      d->remaining[a] = (int)(k1 - k0);
    } else if (e[a] < o[a]) {
      d->step[a] = -1;
      len[a] = o[a] - e[a];
      dist[a] = o[a] - k0 * FVP_DDA_ONE; /* in [0, ONE) */
      d->remaining[a] = (int)(k0 - k1);
    } else {
      d->step[a] = 0;
      len[a] = 0;
      dist[a] = FVP_DDA_ONE;
      d->remaining[a] = 0;
    }
    d->step_len[a] = FVP_DDA_ONE * len[a];
  }

  if (skip_outside) {
    /* Find the crossing that brings the last outside axis into range: the entry. */
    int entry_axis = -1;
    fvp_i64 entry_num = 0, entry_den = 1;
    for (a = 0; a < 3; ++a) {
      fvp_i64 needed;
      if (d->key[a] < 0) {
        if (d->step[a] <= 0) return FVP_RAY_LEFT_GRID;
        needed = -(fvp_i64)d->key[a];
      } else if (d->key[a] >= dim[a]) {
        if (d->step[a] >= 0) return FVP_RAY_LEFT_GRID;
        needed = (fvp_i64)d->key[a] - (dim[a] - 1);
      } else {
        continue;
      }
      if (needed > d->remaining[a]) return FVP_RAY_LEFT_GRID;
      {
        fvp_i64 num = dist[a] + (needed - 1) * FVP_DDA_ONE;
        /* Later parameter wins; at equal parameters the lower axis is stepped last. */
        fvp_i64 lhs = num * entry_den, rhs = entry_num * len[a];
        if (entry_axis < 0 || lhs > rhs) {
          entry_axis = a;
          entry_num = num;
          entry_den = len[a];
        }
      }
    }
    if (entry_axis >= 0) {
      for (a = 0; a < 3; ++a) {
        fvp_i64 n;
        if (a == entry_axis) {
          n = (d->key[a] < 0) ? -(fvp_i64)d->key[a] : (fvp_i64)d->key[a] - (dim[a] - 1);
        } else {
          n = fvp_dda_crossings_before(dist[a], len[a], entry_num, entry_den, a > entry_axis);
          if (n > d->remaining[a]) n = d->remaining[a];
        }
        d->key[a] += d->step[a] * (int)n;
        d->remaining[a] -= (int)n;
        dist[a] += n * FVP_DDA_ONE;
      }
      for (a = 0; a < 3; ++a)
        if (d->key[a] < 0 || d->key[a] >= dim[a]) return FVP_RAY_LEFT_GRID;
    }
  }
  fvp_dda_set_cross_terms(d, dist);
  return 0;
}

FVP_FN unsigned int fvp_dda_init(fvp_dda* d, const fvp_grid_params* g, const float* o_m,
                                 const float* e_m) {
  return fvp_dda_init_ex(d, g, o_m, e_m, 1);
}

/* Axis of the next crossing, or -1 once the end voxel is reached. */
FVP_FN int fvp_dda_next_axis(const fvp_dda* d) {
  int done_x = d->remaining[0] == 0, done_y = d->remaining[1] == 0, done_z = d->remaining[2] == 0;
  int x_first_y, x_first_z, y_first_z;
  if (done_x && done_y && done_z) return -1;
  x_first_y = !done_x && (done_y || d->cross_xy < 0);
  x_first_z = !done_x && (done_z || d->cross_xz < 0);
  y_first_z = !done_y && (done_z || d->cross_yz < 0);
  return x_first_y ? (x_first_z ? 0 : 2) : (y_first_z ? 1 : 2);
}

FVP_FN void fvp_dda_advance(fvp_dda* d, int axis) {
  d->key[axis] += d->step[axis];
  d->remaining[axis] -= 1;
  if (axis == 0) {
    d->cross_xy += d->step_len[1];
    d->cross_xz += d->step_len[2];
  } else if (axis == 1) {
    d->cross_xy -= d->step_len[0];
    d->cross_yz += d->step_len[2];
  } else {
    d->cross_xz -= d->step_len[0];
    d->cross_yz -= d->step_len[1];
  }
}

/* The ray-traversal kernel body: walk until the first voxel at or above the
 * threshold or the end voxel, summing `field` over the visited voxels. */
FVP_FN fvp_ray_result fvp_traverse_ray(const fvp_grid_params* g, float occupied_threshold,
                                       const float* origin_m, const float* end_m,
                                       FVP_GLOBAL const float* occupancy,
                                       FVP_GLOBAL const float* field) {
  fvp_ray_result r;
  fvp_dda d;
  int dim[3], stride[3], index;
  r.steps = 0;
  r.field_sum = 0.0f;
  r.stop_voxel = -1;
  r.status = fvp_dda_init(&d, g, origin_m, end_m);
  if (r.status != 0) return r;
  dim[0] = g->dim_x;
  dim[1] = g->dim_y;
  dim[2] = g->dim_z;
  stride[0] = 1;
  stride[1] = g->dim_x;
  stride[2] = g->dim_x * g->dim_y;
  index = d.key[0] + stride[1] * d.key[1] + stride[2] * d.key[2];
  for (;;) {
    int axis;
    r.steps += 1;
    r.field_sum += field[index];
    if (occupancy[index] >= occupied_threshold) {
      r.status = FVP_RAY_HIT_OCCUPIED;
      r.stop_voxel = index;
      return r;
    }
    axis = fvp_dda_next_axis(&d);
    if (axis < 0) {
      r.status = FVP_RAY_REACHED_END;
      r.stop_voxel = index;
      return r;
    }
    fvp_dda_advance(&d, axis);
    if (d.key[axis] < 0 || d.key[axis] >= dim[axis]) {
      r.status = FVP_RAY_LEFT_GRID;
      return r;
    }
    index += d.step[axis] * stride[axis];
  }
}

#endif /* FVP_DDA_H */
