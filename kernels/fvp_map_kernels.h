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
  /* Bricks the pass computes (work item i: line i % 64 of brick work_bricks[i / 64]):
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

/* Distance in voxels from a squared distance, capped at the radius; correctly rounded
 * (fvp_exact.h), since the gain's weights are read from it. */
FVP_FN float fvp_edt_distance_vox(unsigned int sq, int radius_vox) {
  if (sq >= (unsigned int)(radius_vox * radius_vox)) return (float)radius_vox;
  return fvp_sqrt_rn((float)sq);
}

/* The value a pass reads at the voxel of slot `slot`: 0 on known ROI (axis 0; NaN, unknown,
 * fails the test), the previous pass's squared distance otherwise; FVP_EDT_FAR for none. */
FVP_FN unsigned int fvp_edt_source(const fvp_edt_params* p, int slot, FVP_GLOBAL const float* roi,
                                   FVP_GLOBAL const unsigned int* sq_in) {
  if (p->axis == 0) return roi[slot] > 0.0f ? 0u : FVP_EDT_FAR;
  return sq_in[slot];
}

/* ROI distance field, one separable pass over one line of a work brick: the 8 voxels along
 * p->axis sharing the other two in-brick coordinates (exact squared Euclidean distance within
 * the cap radius; Felzenszwalb-style min-plus over a window). Voxel j's value is the minimum
 * over |k| <= radius of source(j + k) + k^2. Each source voxel of the line's window is read
 * once, its brick's table entry once per brick, and relaxes every output it reaches: the
 * same minimum as a voxel-by-voxel scan at a fraction of the reads. */
FVP_FN void fvp_roi_distance_line(const fvp_edt_params* p, unsigned int item,
                                  FVP_GLOBAL const int* brick_coords, FVP_GLOBAL const int* table,
                                  FVP_GLOBAL const float* roi, FVP_GLOBAL const unsigned int* sq_in,
                                  FVP_GLOBAL unsigned int* sq_out, FVP_GLOBAL float* distance_vox,
                                  FVP_GLOBAL const unsigned int* work_bricks) {
  unsigned int brick = work_bricks[item / FVP_BRICK_LINES], line = item % FVP_BRICK_LINES,
               best[FVP_BRICK_EDGE], v;
  int c[3], first_local[3], stride, radius = p->radius_vox, axis = p->axis;
  int reach = (radius + FVP_BRICK_EDGE - 1) / FVP_BRICK_EDGE, bricks_along, nb, t, j, k, entry;
  int in_brick0, slot;
  c[0] = brick_coords[3 * brick + 0];
  c[1] = brick_coords[3 * brick + 1];
  c[2] = brick_coords[3 * brick + 2];
  /* The line's two fixed in-brick coordinates, in axis order without the pass's axis. */
  first_local[0] = axis == 0 ? 0 : (int)(line & 7u);
  first_local[1] = axis == 1 ? 0 : (axis == 0 ? (int)(line & 7u) : (int)(line >> 3));
  first_local[2] = axis == 2 ? 0 : (int)(line >> 3);
  stride = axis == 0 ? 1 : (axis == 1 ? FVP_BRICK_EDGE : FVP_BRICK_EDGE * FVP_BRICK_EDGE);
  in_brick0 = fvp_local_of(first_local[0], first_local[1], first_local[2]);
  bricks_along = axis == 0 ? p->map.bricks_x : (axis == 1 ? p->map.bricks_y : p->map.bricks_z);
  for (j = 0; j < FVP_BRICK_EDGE; ++j) best[j] = FVP_EDT_FAR;
  for (nb = -reach; nb <= reach; ++nb) {
    int n[3];
    n[0] = c[0];
    n[1] = c[1];
    n[2] = c[2];
    n[axis] += nb;
    if (n[axis] < 0 || n[axis] >= bricks_along) continue; /* outside the grid: none */
    entry = table[n[0] + p->map.bricks_x * (n[1] + p->map.bricks_y * n[2])];
    if (entry < 0) continue; /* unallocated: none */
    for (t = 0; t < FVP_BRICK_EDGE; ++t) {
      int s = nb * FVP_BRICK_EDGE + t; /* the source's offset from the line's first voxel */
      if (s < -radius || s > FVP_BRICK_EDGE - 1 + radius) continue;
      v = fvp_edt_source(p, fvp_slot_of_entry(entry, in_brick0 + t * stride), roi, sq_in);
      if (v == FVP_EDT_FAR) continue;
      for (j = 0; j < FVP_BRICK_EDGE; ++j) {
        k = s - j;
        if (k < -radius || k > radius) continue;
        if (v + (unsigned int)(k * k) < best[j]) best[j] = v + (unsigned int)(k * k);
      }
    }
  }
  for (j = 0; j < FVP_BRICK_EDGE; ++j) {
    slot = (int)brick * FVP_BRICK_VOXELS + in_brick0 + j * stride;
    if (axis < 2)
      sq_out[slot] = best[j];
    else
      distance_vox[slot] = fvp_edt_distance_vox(best[j], radius);
  }
}

/* A neighbour's part in a frontier test: -1 outside the mapped region (ignored), 1 unknown,
 * 0 known. A neighbour in the voxel's own brick reuses its table entry, and one in a brick
 * flagged inside the region skips the sphere test (every voxel of such a brick passes it):
 * the same answer as fvp_in_map and fvp_slot, with fewer reads. */
FVP_FN int fvp_neighbour_unknown(const fvp_bricked_grid* m, FVP_GLOBAL const int* table,
                                 FVP_GLOBAL const float* occupancy, int own_brick, int own_entry,
                                 int nx, int ny, int nz) {
  int brick, entry;
  float occ;
  if (nx < 0 || ny < 0 || nz < 0 || nx >= m->grid.dim_x || ny >= m->grid.dim_y ||
      nz >= m->grid.dim_z)
    return -1;
  brick = fvp_brick_of(m, nx, ny, nz);
  entry = brick == own_brick ? own_entry : table[brick];
  if (m->use_region && !(entry >= 0 && (entry & FVP_BRICK_INSIDE)) &&
      !fvp_region_contains(&m->region, nx, ny, nz))
    return -1;
  if (entry < 0) return 1;
  occ = occupancy[fvp_slot_of_entry(entry, fvp_local_of(nx, ny, nz))];
  return occ != occ;
}

/* Frontier classification of one voxel; returns FVP_FRONTIER_* flags and, for
 * exploration frontiers, the summed offsets away from unknown neighbours. Neighbours
 * outside the mapped region are ignored: they are not unknown space of this map. */
FVP_FN unsigned int fvp_frontier_voxel(const fvp_frontier_params* p, int x, int y, int z,
                                       FVP_GLOBAL const int* table,
                                       FVP_GLOBAL const float* occupancy,
                                       FVP_GLOBAL const float* roi, int* normal) {
  int slot, a, dx, dy, dz, face_unknown = 0, own_brick, own_entry;
  unsigned int flags = 0;
  float occ;
  int is_roi, is_free;
  normal[0] = normal[1] = normal[2] = 0;
  if (!fvp_in_map(&p->map, x, y, z)) return 0;
  own_brick = fvp_brick_of(&p->map, x, y, z);
  own_entry = table[own_brick];
  if (own_entry < 0) return 0;
  slot = fvp_slot_of_entry(own_entry, fvp_local_of(x, y, z));
  occ = occupancy[slot];
  if (occ != occ) return 0; /* unknown voxels are not frontiers */
  is_roi = roi[slot] > 0.0f;
  is_free = !(occ > p->occupied_logodds);
  if (!is_roi && !is_free) return 0;
  /* A frontier needs an unknown face neighbour: most voxels have none, and are settled by
   * their 6 faces before the 26 neighbours that make the normal are read. */
  for (a = 0; a < 6 && !face_unknown; ++a) {
    int step = (a & 1) ? 1 : -1;
    face_unknown =
        fvp_neighbour_unknown(&p->map, table, occupancy, own_brick, own_entry,
                              x + ((a >> 1) == 0 ? step : 0), y + ((a >> 1) == 1 ? step : 0),
                              z + ((a >> 1) == 2 ? step : 0)) == 1;
  }
  if (!face_unknown) return 0;
  for (dz = -1; dz <= 1; ++dz)
    for (dy = -1; dy <= 1; ++dy)
      for (dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0 && dz == 0) continue;
        if (fvp_neighbour_unknown(&p->map, table, occupancy, own_brick, own_entry, x + dx, y + dy,
                                  z + dz) != 1)
          continue;
        normal[0] -= dx;
        normal[1] -= dy;
        normal[2] -= dz;
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

#endif /* FVP_MAP_KERNELS_H */
