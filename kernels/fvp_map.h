/* fvp_map.h: per-voxel map math shared by the C++ reference, the OpenCL kernels and
 * (mirrored in shaders/fvp_map.glsl) the Vulkan shaders: OctoMap's clamped log-odds
 * update, the Cluster Region membership test, and the bricked voxel storage layout.
 * Every expression here rounds the same way on every device (no contraction). */
#ifndef FVP_MAP_H
#define FVP_MAP_H

#include "fvp_dda.h"

/* Bricks of 8x8x8 voxels: storage is allocated a brick at a time, so large sparse
 * volumes (RVP's 1 mm map of the whole observation box) cost only what was seen. */
#define FVP_BRICK_SHIFT 3
#define FVP_BRICK_EDGE 8
#define FVP_BRICK_VOXELS 512
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

/* OctoMap's update: add the hit or miss log-odds, clamp; unknown (NaN) starts at 0. */
FVP_FN float fvp_logodds_update(float value, float delta, float clamp_min, float clamp_max) {
  float v = (value != value) ? 0.0f : value;
  v = v + delta;
  if (v < clamp_min) v = clamp_min;
  if (v > clamp_max) v = clamp_max;
  return v;
}

#endif /* FVP_MAP_H */
