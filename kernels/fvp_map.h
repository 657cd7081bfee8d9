/* fvp_map.h: per-voxel map math shared by the C++ reference, the OpenCL kernels and
 * (mirrored in shaders/fvp_map.glsl) the Vulkan shaders: OctoMap's clamped log-odds
 * update, the Cluster Region membership test, the bricked voxel storage layout (slot
 * arithmetic, used by host code too) and the bricked ray walker that scan integration and
 * the information-gain kernels share. Every expression here rounds the same way on every
 * device (no contraction). */
#ifndef FVP_MAP_H
#define FVP_MAP_H

#include "fvp_dda.h"

/* Bricks of 8x8x8 voxels: storage is allocated a brick at a time, so large sparse
 * volumes (RVP's 1 mm map of the whole observation box) cost only what was seen. */
#define FVP_BRICK_SHIFT 3
#define FVP_BRICK_EDGE 8
#define FVP_BRICK_VOXELS 512
#define FVP_BRICK_LINES 64 /* lines of 8 voxels along one axis in a brick */
#define FVP_NO_BRICK (-1)
/* Brick table entries: the allocation index, plus this flag on bricks whose voxels all
 * lie inside the region (with a margin), so walks skip the per-voxel sphere test there. */
#define FVP_BRICK_INSIDE 0x40000000
#define FVP_BRICK_INDEX_MASK 0x3fffffff

/* The Cluster Region in a grid's voxel units: voxel (x, y, z) belongs to it when its
 * centre lies within the sphere. */
typedef struct fvp_region {
  float center_x_vox, center_y_vox, center_z_vox;
  float radius_sq_vox;
} fvp_region;

FVP_FN int fvp_region_contains(const fvp_region* r, int x, int y, int z) {
  float dx = ((float)x + 0.5f) - r->center_x_vox;
  float dy = ((float)y + 0.5f) - r->center_y_vox;
  float dz = ((float)z + 0.5f) - r->center_z_vox;
  float d2 = dx * dx;
  d2 = d2 + dy * dy;
  d2 = d2 + dz * dz;
  return d2 <= r->radius_sq_vox;
}

/* A bricked grid: voxel geometry (dims multiples of 8) and the brick table's dims. */
typedef struct fvp_bricked_grid {
  fvp_grid_params grid;
  int bricks_x, bricks_y, bricks_z;
  int use_region; /* 1: only voxels inside `region` are mapped (fine map) */
  fvp_region region;
} fvp_bricked_grid;

/* Index of the brick holding voxel (x, y, z) in the brick table. */
FVP_FN int fvp_brick_of(const fvp_bricked_grid* m, int x, int y, int z) {
  return (x >> FVP_BRICK_SHIFT) +
         m->bricks_x * ((y >> FVP_BRICK_SHIFT) + m->bricks_y * (z >> FVP_BRICK_SHIFT));
}

/* Index of voxel (x, y, z) inside its brick. */
FVP_FN int fvp_local_of(int x, int y, int z) {
  return (x & 7) + 8 * ((y & 7) + 8 * (z & 7));
}

/* Slot of a voxel given its brick's table entry: allocation index * 512 + in_brick index. */
FVP_FN int fvp_slot_of_entry(int entry, int in_brick) {
  return (entry & FVP_BRICK_INDEX_MASK) * FVP_BRICK_VOXELS + in_brick;
}

/* Slot of voxel (x, y, z) (inside the grid), or -1 when its brick is not allocated. */
FVP_FN int fvp_slot(const fvp_bricked_grid* m, FVP_GLOBAL const int* table, int x, int y, int z) {
  int entry = table[fvp_brick_of(m, x, y, z)];
  if (entry < 0) return -1;
  return fvp_slot_of_entry(entry, fvp_local_of(x, y, z));
}

/* True when voxel (x, y, z) lies in the grid and, for region maps, in the region. */
FVP_FN int fvp_in_map(const fvp_bricked_grid* m, int x, int y, int z) {
  if (x < 0 || y < 0 || z < 0 || x >= m->grid.dim_x || y >= m->grid.dim_y || z >= m->grid.dim_z)
    return 0;
  return !m->use_region || fvp_region_contains(&m->region, x, y, z);
}

/* Voxel coordinates of a slot, given the allocated bricks' grid coordinates (3 ints each). */
FVP_FN void fvp_slot_voxel(FVP_GLOBAL const int* brick_coords, unsigned int slot, int* x, int* y,
                           int* z) {
  unsigned int brick = slot / FVP_BRICK_VOXELS, in_brick = slot % FVP_BRICK_VOXELS;
  *x = brick_coords[3 * brick + 0] * FVP_BRICK_EDGE + (int)(in_brick & 7u);
  *y = brick_coords[3 * brick + 1] * FVP_BRICK_EDGE + (int)((in_brick >> 3) & 7u);
  *z = brick_coords[3 * brick + 2] * FVP_BRICK_EDGE + (int)(in_brick >> 6);
}

/* The bricked walker: the exact DDA (fvp_dda.h) over bricked storage, tracking the
 * current brick's table entry and the voxel's in_brick index so that the table is read only
 * when the walk enters a new brick. Use:
 *   if (fvp_walk_init(&w, m, o, e, table) != 0) return;      (status as fvp_dda_init)
 *   for (;;) { ... w.d.key, w.entry (< 0: unallocated), fvp_walk_slot(&w) ...
 *              axis = fvp_dda_next_axis(&w.d); if (axis < 0) break;   (the end voxel)
 *              if (!fvp_walk_step(&w, m, axis, table)) break; }       (left the grid) */
typedef struct fvp_walk {
  fvp_dda d;
  int brick;    /* index in the brick table */
  int entry;    /* table[brick]: allocation index | flags, or FVP_NO_BRICK */
  int in_brick; /* index of the current voxel in its brick */
} fvp_walk;

FVP_FN unsigned int fvp_walk_init(fvp_walk* w, const fvp_bricked_grid* m, const float* o_m,
                                  const float* e_m, FVP_GLOBAL const int* table) {
  unsigned int status = fvp_dda_init(&w->d, &m->grid, o_m, e_m);
  if (status != 0) return status;
  w->brick = fvp_brick_of(m, w->d.key[0], w->d.key[1], w->d.key[2]);
  w->entry = table[w->brick];
  w->in_brick = fvp_local_of(w->d.key[0], w->d.key[1], w->d.key[2]);
  return 0;
}

/* Slot of the current voxel; only meaningful when w->entry >= 0. */
FVP_FN int fvp_walk_slot(const fvp_walk* w) {
  return fvp_slot_of_entry(w->entry, w->in_brick);
}

/* True when the current voxel is mapped: in the region (bricks flagged inside skip the
 * sphere test) or the map has no region. */
FVP_FN int fvp_walk_mapped(const fvp_walk* w, const fvp_bricked_grid* m) {
  return !m->use_region || (w->entry >= 0 && (w->entry & FVP_BRICK_INSIDE)) ||
         fvp_region_contains(&m->region, w->d.key[0], w->d.key[1], w->d.key[2]);
}

/* Steps to the next voxel along `axis` (from fvp_dda_next_axis); 0 when it left the grid. */
FVP_FN int fvp_walk_step(fvp_walk* w, const fvp_bricked_grid* m, int axis,
                         FVP_GLOBAL const int* table) {
  int dim = axis == 0 ? m->grid.dim_x : (axis == 1 ? m->grid.dim_y : m->grid.dim_z);
  int brick_stride = axis == 0 ? 1 : (axis == 1 ? m->bricks_x : m->bricks_x * m->bricks_y);
  int local_stride = axis == 0 ? 1 : (axis == 1 ? 8 : 64);
  int key;
  fvp_dda_advance(&w->d, axis);
  key = w->d.key[axis];
  if (key < 0 || key >= dim) return 0;
  if ((key & 7) == (w->d.step[axis] > 0 ? 0 : 7)) {
    w->brick += w->d.step[axis] * brick_stride;
    w->entry = table[w->brick];
    w->in_brick -= w->d.step[axis] * 7 * local_stride;
  } else {
    w->in_brick += w->d.step[axis] * local_stride;
  }
  return 1;
}

/* OctoMap's update: add the hit or miss log-odds, clamp; unknown (NaN) starts at 0. */
FVP_FN float fvp_logodds_update(float value, float delta, float clamp_min, float clamp_max) {
  float v = (value != value) ? 0.0f : value;
  v = v + delta;
  if (v < clamp_min) v = clamp_min;
  if (v > clamp_max) v = clamp_max;
  return v;
}

#endif /* FVP_MAP_H */
