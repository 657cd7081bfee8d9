/* fvp_map_kernels.h: bodies of the map kernels (scan integration, ROI distance field,
 * frontier extraction) over bricked voxel storage. C subset shared by the C++ reference
 * backend and the OpenCL kernels; shaders/fvp_map_kernels.glsl mirrors it.
 *
 * Storage: a brick table (int per 8^3 brick of the grid; FVP_NO_BRICK where nothing is
 * allocated) and pools indexed by slot = brick * 512 + local voxel. Occupancy and ROI
 * pools hold log-odds, NaN for unknown.
 *
 * Determinism: scan integration runs in two passes. The mark pass walks every ray and
 * only stores the constant 1 into per-slot mark planes (free, hit, roi): racing stores of
 * the same value leave the same result in any order. The update pass then changes each
 * voxel once, from its marks, by one work item. */
#ifndef FVP_MAP_KERNELS_H
#define FVP_MAP_KERNELS_H

#include "fvp_dda.h"
#include "fvp_map.h"

#ifdef __OPENCL_VERSION__
#define FVP_MARK(ptr) (*(ptr) = 1)
#define FVP_ATOMIC_ADD(ptr, v) atomic_add((ptr), (v))
#define FVP_ATOMIC_INC(ptr) atomic_inc(ptr)
#define FVP_SQRTF sqrt
#else
/* Relaxed atomic stores: the racing same-value stores are well defined in C++ too. */
#define FVP_MARK(ptr) __atomic_store_n((ptr), 1, __ATOMIC_RELAXED)
#define FVP_ATOMIC_ADD(ptr, v) __atomic_fetch_add((ptr), (v), __ATOMIC_RELAXED)
#define FVP_ATOMIC_INC(ptr) __atomic_fetch_add((ptr), 1u, __ATOMIC_RELAXED)
#define FVP_SQRTF sqrtf
#endif

/* Point flags */
#define FVP_POINT_HIT 1u /* the end point is a measured surface (not cut at max range) */
#define FVP_POINT_ROI 2u /* the end point is a segmented fruitlet pixel */

/* Frontier flags */
#define FVP_FRONTIER_ROI 1u     /* known ROI voxel next to unknown space */
#define FVP_FRONTIER_EXPLORE 2u /* known free voxel next to unknown space */

/* Squared distance meaning "no ROI voxel within the cap". */
#define FVP_EDT_FAR 0x7fffffffu

typedef struct fvp_scan_point {
  float x_m, y_m, z_m;
  unsigned int flags; /* FVP_POINT_* */
} fvp_scan_point;

/* A bricked grid: voxel geometry (dims multiples of 8) and the brick table's dims. */
typedef struct fvp_bricked_grid {
  fvp_grid_params grid;
  int bricks_x, bricks_y, bricks_z;
  int use_region; /* 1: only voxels inside `region` are mapped (fine map) */
  fvp_region region;
} fvp_bricked_grid;

typedef struct fvp_scan_params {
  fvp_bricked_grid map;
  float sensor_x_m, sensor_y_m, sensor_z_m;
  unsigned int point_count;
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

/* Slot of voxel (x, y, z), or -1 when its brick is not allocated. */
FVP_FN int fvp_slot(const fvp_bricked_grid* m, FVP_GLOBAL const int* table, int x, int y, int z) {
  int b = (x >> FVP_BRICK_SHIFT) + m->bricks_x * ((y >> FVP_BRICK_SHIFT) + m->bricks_y * (z >> FVP_BRICK_SHIFT));
  int brick = table[b];
  if (brick < 0) return -1;
  return (brick & FVP_BRICK_INDEX_MASK) * FVP_BRICK_VOXELS + (x & 7) + 8 * ((y & 7) + 8 * (z & 7));
}

FVP_FN int fvp_brick_of(const fvp_bricked_grid* m, int x, int y, int z) {
  return (x >> FVP_BRICK_SHIFT) + m->bricks_x * ((y >> FVP_BRICK_SHIFT) + m->bricks_y * (z >> FVP_BRICK_SHIFT));
}

FVP_FN int fvp_in_map(const fvp_bricked_grid* m, int x, int y, int z) {
  if (x < 0 || y < 0 || z < 0 || x >= m->grid.dim_x || y >= m->grid.dim_y || z >= m->grid.dim_z)
    return 0;
  return !m->use_region || fvp_region_contains(&m->region, x, y, z);
}

/* Voxel coordinates of a slot, given the brick's grid coordinates table. */
FVP_FN void fvp_slot_voxel(FVP_GLOBAL const int* brick_coords, unsigned int slot, int* x, int* y,
                           int* z) {
  unsigned int brick = slot / FVP_BRICK_VOXELS, in_brick = slot % FVP_BRICK_VOXELS;
  *x = brick_coords[3 * brick + 0] * FVP_BRICK_EDGE + (int)(in_brick & 7u);
  *y = brick_coords[3 * brick + 1] * FVP_BRICK_EDGE + (int)((in_brick >> 3) & 7u);
  *z = brick_coords[3 * brick + 2] * FVP_BRICK_EDGE + (int)(in_brick >> 6);
}

/* Mark pass for one point: free marks along the ray, a hit (and ROI) mark at its end.
 * Voxels in unallocated bricks flag their brick in `missing` (and missing[brick_count])
 * for the host to allocate and re-run: marks are idempotent. The brick table is read only
 * when the walk enters a new brick. */
FVP_FN void fvp_scan_mark_point(const fvp_scan_params* p, fvp_scan_point pt,
                                FVP_GLOBAL const int* table, FVP_GLOBAL unsigned char* free_marks,
                                FVP_GLOBAL unsigned char* hit_marks, FVP_GLOBAL unsigned char* roi_marks,
                                FVP_GLOBAL unsigned int* missing, int brick_count) {
  fvp_dda d;
  float o[3], e[3];
  int dim[3], brick_stride[3], local_stride[3];
  int brick, entry, local_index;
  o[0] = p->sensor_x_m;
  o[1] = p->sensor_y_m;
  o[2] = p->sensor_z_m;
  e[0] = pt.x_m;
  e[1] = pt.y_m;
  e[2] = pt.z_m;
  if (fvp_dda_init(&d, &p->map.grid, o, e) != 0) return;
  dim[0] = p->map.grid.dim_x;
  dim[1] = p->map.grid.dim_y;
  dim[2] = p->map.grid.dim_z;
  brick_stride[0] = 1;
  brick_stride[1] = p->map.bricks_x;
  brick_stride[2] = p->map.bricks_x * p->map.bricks_y;
  local_stride[0] = 1;
  local_stride[1] = 8;
  local_stride[2] = 64;
  brick = fvp_brick_of(&p->map, d.key[0], d.key[1], d.key[2]);
  entry = table[brick];
  local_index = (d.key[0] & 7) + 8 * ((d.key[1] & 7) + 8 * (d.key[2] & 7));
  for (;;) {
    int axis = fvp_dda_next_axis(&d);
    int last = axis < 0;
    int mapped = !p->map.use_region || (entry >= 0 && (entry & FVP_BRICK_INSIDE)) ||
                 fvp_region_contains(&p->map.region, d.key[0], d.key[1], d.key[2]);
    if (mapped) {
      if (entry < 0) {
        FVP_MARK(&missing[brick]);
        FVP_MARK(&missing[brick_count]);
      } else {
        int slot = (entry & FVP_BRICK_INDEX_MASK) * FVP_BRICK_VOXELS + local_index;
        if (!last) {
          FVP_MARK(&free_marks[slot]);
        } else if (pt.flags & FVP_POINT_HIT) {
          FVP_MARK(&hit_marks[slot]);
          if (pt.flags & FVP_POINT_ROI) FVP_MARK(&roi_marks[slot]);
        }
        /* The cut end of a ray beyond max range is neither free nor hit (OctoMap's maxrange). */
      }
    }
    if (last) return;
    fvp_dda_advance(&d, axis);
    if (d.key[axis] < 0 || d.key[axis] >= dim[axis]) return;
    if ((d.key[axis] & 7) == (d.step[axis] > 0 ? 0 : 7)) {
      brick += d.step[axis] * brick_stride[axis];
      entry = table[brick];
      local_index -= d.step[axis] * 7 * local_stride[axis];
    } else {
      local_index += d.step[axis] * local_stride[axis];
    }
  }
}

/* Update pass over slots [first, first + count): apply each voxel's marks once and clear
 * them. Returns the number of voxels updated. */
FVP_FN unsigned int fvp_scan_update_slots(const fvp_update_params* p, unsigned int first, unsigned int count,
                                          FVP_GLOBAL unsigned char* free_marks, FVP_GLOBAL unsigned char* hit_marks,
                                          FVP_GLOBAL unsigned char* roi_marks, FVP_GLOBAL float* occupancy,
                                          FVP_GLOBAL float* roi) {
  unsigned int updated = 0, s;
  for (s = first; s < first + count; ++s) {
    if (hit_marks[s]) {
      occupancy[s] = fvp_logodds_update(occupancy[s], p->hit_logodds, p->clamp_min_logodds, p->clamp_max_logodds);
      if (p->has_roi)
        roi[s] = fvp_logodds_update(roi[s], roi_marks[s] ? p->hit_logodds : p->miss_logodds,
                                    p->clamp_min_logodds, p->clamp_max_logodds);
      ++updated;
    } else if (free_marks[s]) {
      occupancy[s] = fvp_logodds_update(occupancy[s], p->miss_logodds, p->clamp_min_logodds, p->clamp_max_logodds);
      ++updated;
    }
    free_marks[s] = 0;
    hit_marks[s] = 0;
    roi_marks[s] = 0;
  }
  return updated;
}

/* ROI distance field, one separable pass for one voxel (exact squared Euclidean distance
 * within the cap radius; Felzenszwalb-style min-plus over a window). axis 0 seeds from
 * the ROI log-odds (known ROI: roi > 0); axes 1 and 2 read the previous pass. */
FVP_FN unsigned int fvp_edt_pass_voxel(const fvp_edt_params* p, int axis, int x, int y, int z,
                                       FVP_GLOBAL const int* table, FVP_GLOBAL const float* roi,
                                       FVP_GLOBAL const unsigned int* sq_in) {
  unsigned int best = FVP_EDT_FAR;
  int k;
  for (k = -p->radius_vox; k <= p->radius_vox; ++k) {
    int nx = x + (axis == 0 ? k : 0), ny = y + (axis == 1 ? k : 0), nz = z + (axis == 2 ? k : 0);
    int slot;
    unsigned int v;
    if (nx < 0 || ny < 0 || nz < 0 || nx >= p->map.grid.dim_x || ny >= p->map.grid.dim_y || nz >= p->map.grid.dim_z)
      continue;
    slot = fvp_slot(&p->map, table, nx, ny, nz);
    if (slot < 0) continue;
    if (axis == 0) {
      if (!(roi[slot] > 0.0f)) continue; /* NaN (unknown) fails too */
      v = 0u;
    } else {
      v = sq_in[slot];
      if (v == FVP_EDT_FAR) continue;
    }
    v += (unsigned int)(k * k);
    if (v < best) best = v;
  }
  return best;
}

/* Distance in voxels from a squared distance, capped at the radius. */
FVP_FN float fvp_edt_distance_vox(unsigned int sq, int radius_vox) {
  if (sq >= (unsigned int)(radius_vox * radius_vox)) return (float)radius_vox;
  return FVP_SQRTF((float)sq);
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
                                       FVP_GLOBAL const int* table, FVP_GLOBAL const float* occupancy,
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

#endif /* FVP_MAP_KERNELS_H */
