/* fvp_map_kernels.h: bodies of the map kernels (scan integration, ROI distance field,
 * frontier extraction) over bricked voxel storage. C subset shared by the C++ reference
 * backend and the OpenCL kernels; shaders/fvp_map_kernels.glsl has a GLSL function of the
 * same name for each function here.
 *
 * Storage (fvp_map.h): a brick table (int per 8^3 brick of the grid; FVP_NO_BRICK where
 * nothing is allocated) and channels indexed by slot = brick * 512 + local voxel.
 * Occupancy and ROI channels hold log-odds, NaN for unknown.
 *
 * Determinism: scan integration runs in two passes. The mark pass walks every ray and only
 * ORs constant bits into the per-slot marks: the result is the same in any order. The
 * update pass then changes each voxel once, from its marks, by one work item. */
#ifndef FVP_MAP_KERNELS_H
#define FVP_MAP_KERNELS_H

#include "fvp_dda.h"
#include "fvp_exact.h"
#include "fvp_map.h"

#ifdef __OPENCL_VERSION__
#define FVP_ATOMIC_OR(ptr, v) atomic_or((ptr), (v))
#define FVP_ATOMIC_ADD(ptr, v) atomic_add((ptr), (v))
#define FVP_ATOMIC_INC(ptr) atomic_inc(ptr)
#define FVP_LOAD(ptr) (*(ptr))
#define FVP_FLAG(ptr) (*(ptr) = 1u)
#else
#define FVP_ATOMIC_OR(ptr, v) __atomic_fetch_or((ptr), (v), __ATOMIC_RELAXED)
#define FVP_ATOMIC_ADD(ptr, v) __atomic_fetch_add((ptr), (v), __ATOMIC_RELAXED)
#define FVP_ATOMIC_INC(ptr) __atomic_fetch_add((ptr), 1u, __ATOMIC_RELAXED)
#define FVP_LOAD(ptr) __atomic_load_n((ptr), __ATOMIC_RELAXED)
/* Racing stores of the same constant: relaxed atomics keep them well defined in C++. */
#define FVP_FLAG(ptr) __atomic_store_n((ptr), 1u, __ATOMIC_RELAXED)
#endif

/* Point flags */
#define FVP_POINT_HIT 1u /* the end point is a measured surface (not cut at max range) */
#define FVP_POINT_ROI 2u /* the end point is a segmented fruitlet pixel */

/* Scan marks: one byte lane per slot in 32-bit words (GLSL has no portable byte stores). */
#define FVP_MARK_FREE 1u
#define FVP_MARK_HIT 2u
#define FVP_MARK_ROI 4u

/* Frontier flags */
#define FVP_FRONTIER_ROI 1u     /* known ROI voxel next to unknown space */
#define FVP_FRONTIER_EXPLORE 2u /* known free voxel next to unknown space */

/* Squared distance meaning "no ROI voxel within the cap". */
#define FVP_EDT_FAR 0x7fffffffu

/* Slots per work item of the update pass. */
#define FVP_UPDATE_CHUNK 64u

typedef struct fvp_scan_point {
  float x_m, y_m, z_m;
  unsigned int flags; /* FVP_POINT_* */
} fvp_scan_point;

typedef struct fvp_scan_params {
  fvp_bricked_grid map;
  float sensor_x_m, sensor_y_m, sensor_z_m;
  unsigned int point_count;
  unsigned int slot_count; /* slots of the channels (the marks hold one byte lane each) */
  int brick_count;         /* bricks in the table; missing[brick_count] flags "any missing" */
} fvp_scan_params;

typedef struct fvp_update_params {
  unsigned int slot_count; /* multiple of 512 */
  float hit_logodds, miss_logodds, clamp_min_logodds, clamp_max_logodds;
  int has_roi;
} fvp_update_params;

typedef struct fvp_edt_params {
  fvp_bricked_grid map;
  int radius_vox; /* the cap: distances beyond it read as the cap */
  unsigned int slot_count;
  int axis; /* the pass: 0 seeds from the ROI channel, 1 and 2 read the previous pass */
  /* Bricks the pass computes (work item i: voxel i % 512 of brick work_bricks[i / 512]):
   * those closer than the radius to a brick holding ROI. The host fills every other slot's
   * pass values with FVP_EDT_FAR and its distance with the cap. */
  unsigned int work_brick_count;
} fvp_edt_params;

typedef struct fvp_frontier_params {
  fvp_bricked_grid map;
  float occupied_logodds; /* occupied when log-odds > this */
  unsigned int slot_count;
  unsigned int capacity; /* entries the output list holds */
} fvp_frontier_params;

/* One frontier voxel. For exploration frontiers, normal_* is the integer sum of the
 * offsets pointing away from its unknown 26-neighbours (normalised on the host). */
typedef struct fvp_frontier {
  int x, y, z;
  unsigned int flags;
  int normal_x, normal_y, normal_z;
  int pad;
} fvp_frontier;

/* Sets mark bits of one slot. Reading first skips the atomic where the bits are already
 * set: most rays of a view cross the same voxels near the sensor. */
FVP_FN void fvp_mark(FVP_GLOBAL unsigned int* marks, int slot, unsigned int bits) {
  FVP_GLOBAL unsigned int* word = marks + (slot >> 2);
  unsigned int lane_bits = bits << (8 * (slot & 3));
  if ((FVP_LOAD(word) & lane_bits) != lane_bits) FVP_ATOMIC_OR(word, lane_bits);
}

/* Mark pass for one point: free marks along the ray, a hit (and ROI) mark at its end.
 * Voxels in unallocated bricks flag their brick in `missing` (and missing[brick_count])
 * for the host to allocate and re-run: marks are idempotent. */
FVP_FN void fvp_scan_mark_point(const fvp_scan_params* p, fvp_scan_point pt,
                                FVP_GLOBAL const int* table, FVP_GLOBAL unsigned int* marks,
                                FVP_GLOBAL unsigned int* missing) {
  fvp_walk w;
  float o[3], e[3];
  o[0] = p->sensor_x_m;
  o[1] = p->sensor_y_m;
  o[2] = p->sensor_z_m;
  e[0] = pt.x_m;
  e[1] = pt.y_m;
  e[2] = pt.z_m;
  if (fvp_walk_init(&w, &p->map, o, e, table) != 0) return;
  for (;;) {
    int axis = fvp_dda_next_axis(&w.d);
    int last = axis < 0;
    if (fvp_walk_mapped(&w, &p->map)) {
      if (w.entry < 0) {
        FVP_FLAG(&missing[w.brick]);
        FVP_FLAG(&missing[p->brick_count]);
      } else if (!last) {
        fvp_mark(marks, fvp_walk_slot(&w), FVP_MARK_FREE);
      } else if (pt.flags & FVP_POINT_HIT) {
        fvp_mark(marks, fvp_walk_slot(&w),
                 (pt.flags & FVP_POINT_ROI) ? (FVP_MARK_HIT | FVP_MARK_ROI) : FVP_MARK_HIT);
      }
      /* The cut end of a ray beyond max range is neither free nor hit (OctoMap's maxrange). */
    }
    if (last || !fvp_walk_step(&w, &p->map, axis, table)) return;
  }
}

/* Update pass over slots [first, first + FVP_UPDATE_CHUNK): apply each voxel's marks once
 * and clear them. Returns the number of voxels updated. */
FVP_FN unsigned int fvp_scan_update_chunk(const fvp_update_params* p, unsigned int first,
                                          FVP_GLOBAL unsigned int* marks,
                                          FVP_GLOBAL float* occupancy, FVP_GLOBAL float* roi) {
  unsigned int updated = 0, w, lane;
  for (w = first >> 2; w < (first + FVP_UPDATE_CHUNK) >> 2; ++w) {
    unsigned int word = marks[w];
    if (word == 0u) continue;
    for (lane = 0; lane < 4u; ++lane) {
      unsigned int m = (word >> (8u * lane)) & 0xffu;
      unsigned int s = w * 4u + lane;
      if (m & FVP_MARK_HIT) {
        occupancy[s] = fvp_logodds_update(occupancy[s], p->hit_logodds, p->clamp_min_logodds,
                                          p->clamp_max_logodds);
        if (p->has_roi)
          roi[s] = fvp_logodds_update(roi[s], (m & FVP_MARK_ROI) ? p->hit_logodds : p->miss_logodds,
                                      p->clamp_min_logodds, p->clamp_max_logodds);
        ++updated;
      } else if (m & FVP_MARK_FREE) {
        occupancy[s] = fvp_logodds_update(occupancy[s], p->miss_logodds, p->clamp_min_logodds,
                                          p->clamp_max_logodds);
        ++updated;
      }
    }
    marks[w] = 0u;
  }
  return updated;
}

/* One work item of the update pass: chunk `item` of FVP_UPDATE_CHUNK slots. Adds the number
 * of updated voxels to *updated and flags the chunk's brick in changed_bricks (one uint per
 * allocated brick), so the host refreshes only what changed. */
FVP_FN void fvp_scan_update_item(const fvp_update_params* p, unsigned int item,
                                 FVP_GLOBAL unsigned int* marks, FVP_GLOBAL float* occupancy,
                                 FVP_GLOBAL float* roi, FVP_GLOBAL unsigned int* updated,
                                 FVP_GLOBAL unsigned int* changed_bricks) {
  unsigned int first = item * FVP_UPDATE_CHUNK;
  unsigned int n = fvp_scan_update_chunk(p, first, marks, occupancy, roi);
  if (n == 0u) return;
  FVP_ATOMIC_ADD(updated, n);
  FVP_FLAG(&changed_bricks[first / FVP_BRICK_VOXELS]);
}

/* One term of a pass's minimum: the squared distance through the voxel k steps along the
 * pass's axis, FVP_EDT_FAR where there is none. */
FVP_FN unsigned int fvp_edt_term(const fvp_edt_params* p, int x, int y, int z, int k,
                                 FVP_GLOBAL const int* table, FVP_GLOBAL const float* roi,
                                 FVP_GLOBAL const unsigned int* sq_in) {
  int axis = p->axis;
  int nx = x + (axis == 0 ? k : 0), ny = y + (axis == 1 ? k : 0), nz = z + (axis == 2 ? k : 0);
  int slot;
  unsigned int v;
  if (nx < 0 || ny < 0 || nz < 0 || nx >= p->map.grid.dim_x || ny >= p->map.grid.dim_y ||
      nz >= p->map.grid.dim_z)
    return FVP_EDT_FAR;
  slot = fvp_slot(&p->map, table, nx, ny, nz);
  if (slot < 0) return FVP_EDT_FAR;
  if (axis == 0) {
    if (!(roi[slot] > 0.0f)) return FVP_EDT_FAR; /* NaN (unknown) fails too */
    v = 0u;
  } else {
    v = sq_in[slot];
    if (v == FVP_EDT_FAR) return FVP_EDT_FAR;
  }
  return v + (unsigned int)(k * k);
}

/* ROI distance field, one separable pass for one voxel (exact squared Euclidean distance
 * within the cap radius; Felzenszwalb-style min-plus over a window). axis 0 seeds from
 * the ROI log-odds (known ROI: roi > 0); axes 1 and 2 read the previous pass. */
/* The minimum over k in [-radius, radius] of the terms, nearest k first: every term at
 * |k| = d is at least d^2, so the scan stops once d^2 reaches the best found (the same
 * minimum). */
FVP_FN unsigned int fvp_edt_pass_voxel(const fvp_edt_params* p, int x, int y, int z,
                                       FVP_GLOBAL const int* table, FVP_GLOBAL const float* roi,
                                       FVP_GLOBAL const unsigned int* sq_in) {
  unsigned int best = fvp_edt_term(p, x, y, z, 0, table, roi, sq_in), v;
  int d;
  for (d = 1; d <= p->radius_vox && (unsigned int)(d * d) < best; ++d) {
    v = fvp_edt_term(p, x, y, z, -d, table, roi, sq_in);
    if (v < best) best = v;
    v = fvp_edt_term(p, x, y, z, d, table, roi, sq_in);
    if (v < best) best = v;
  }
  return best;
}

/* Distance in voxels from a squared distance, capped at the radius; correctly rounded
 * (fvp_exact.h), since the gain's weights are read from it. */
FVP_FN float fvp_edt_distance_vox(unsigned int sq, int radius_vox) {
  if (sq >= (unsigned int)(radius_vox * radius_vox)) return (float)radius_vox;
  return fvp_sqrt_rn((float)sq);
}

FVP_FN int fvp_voxel_unknown(const fvp_bricked_grid* m, FVP_GLOBAL const int* table,
                             FVP_GLOBAL const float* occupancy, int x, int y, int z) {
  int slot = fvp_slot(m, table, x, y, z);
  if (slot < 0) return 1;
  return occupancy[slot] != occupancy[slot];
}

/* Frontier classification of one voxel; returns FVP_FRONTIER_* flags and, for
 * exploration frontiers, the summed offsets away from unknown neighbours. Neighbours
 * outside the mapped region are ignored: they are not unknown space of this map. */
FVP_FN unsigned int fvp_frontier_voxel(const fvp_frontier_params* p, int x, int y, int z,
                                       FVP_GLOBAL const int* table,
                                       FVP_GLOBAL const float* occupancy,
                                       FVP_GLOBAL const float* roi, int* normal) {
  int slot, dx, dy, dz, face_unknown = 0;
  unsigned int flags = 0;
  float occ;
  int is_roi, is_free;
  normal[0] = normal[1] = normal[2] = 0;
  if (!fvp_in_map(&p->map, x, y, z)) return 0;
  slot = fvp_slot(&p->map, table, x, y, z);
  if (slot < 0) return 0;
  occ = occupancy[slot];
  if (occ != occ) return 0; /* unknown voxels are not frontiers */
  is_roi = roi[slot] > 0.0f;
  is_free = !(occ > p->occupied_logodds);
  if (!is_roi && !is_free) return 0;
  for (dz = -1; dz <= 1; ++dz)
    for (dy = -1; dy <= 1; ++dy)
      for (dx = -1; dx <= 1; ++dx) {
        int nx = x + dx, ny = y + dy, nz = z + dz;
        int manhattan = (dx != 0) + (dy != 0) + (dz != 0);
        if (manhattan == 0 || !fvp_in_map(&p->map, nx, ny, nz)) continue;
        if (!fvp_voxel_unknown(&p->map, table, occupancy, nx, ny, nz)) continue;
        if (manhattan == 1) face_unknown = 1;
        normal[0] -= dx;
        normal[1] -= dy;
        normal[2] -= dz;
      }
  if (!face_unknown) {
    normal[0] = normal[1] = normal[2] = 0;
    return 0;
  }
  if (is_roi) flags |= FVP_FRONTIER_ROI;
  if (is_free) flags |= FVP_FRONTIER_EXPLORE;
  return flags;
}

/* Classifies one voxel and appends it to `frontiers` when it is a frontier (up to
 * p->capacity entries; *count receives the total found, which may exceed it). */
FVP_FN void fvp_frontier_append(const fvp_frontier_params* p, int x, int y, int z,
                                FVP_GLOBAL const int* table, FVP_GLOBAL const float* occupancy,
                                FVP_GLOBAL const float* roi, FVP_GLOBAL fvp_frontier* frontiers,
                                FVP_GLOBAL unsigned int* count) {
  int normal[3];
  unsigned int flags = fvp_frontier_voxel(p, x, y, z, table, occupancy, roi, normal);
  unsigned int index;
  fvp_frontier f;
  if (!flags) return;
  index = FVP_ATOMIC_INC(count);
  if (index >= p->capacity) return;
  f.x = x;
  f.y = y;
  f.z = z;
  f.flags = flags;
  f.normal_x = normal[0];
  f.normal_y = normal[1];
  f.normal_z = normal[2];
  f.pad = 0;
  frontiers[index] = f;
}

/* Slot of work item i of a pass over a list of bricks (allocation indices). */
FVP_FN unsigned int fvp_work_slot(FVP_GLOBAL const unsigned int* work_bricks, unsigned int i) {
  return work_bricks[i / FVP_BRICK_VOXELS] * FVP_BRICK_VOXELS + i % FVP_BRICK_VOXELS;
}

/* One ROI distance pass (p->axis) for one slot: axes 0 and 1 write the squared distance
 * to sq_out, axis 2 the capped distance in voxels to distance_vox. */
FVP_FN void fvp_roi_distance_slot(const fvp_edt_params* p, unsigned int slot,
                                  FVP_GLOBAL const int* brick_coords, FVP_GLOBAL const int* table,
                                  FVP_GLOBAL const float* roi, FVP_GLOBAL const unsigned int* sq_in,
                                  FVP_GLOBAL unsigned int* sq_out, FVP_GLOBAL float* distance_vox) {
  int x, y, z;
  unsigned int best;
  fvp_slot_voxel(brick_coords, slot, &x, &y, &z);
  best = fvp_edt_pass_voxel(p, x, y, z, table, roi, sq_in);
  if (p->axis < 2)
    sq_out[slot] = best;
  else
    distance_vox[slot] = fvp_edt_distance_vox(best, p->radius_vox);
}

#endif /* FVP_MAP_KERNELS_H */
