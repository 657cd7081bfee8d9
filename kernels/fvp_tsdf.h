/* Projective TSDF integration (docs/design.md section 1 step 2, voxblox's weighting): the
 * per-voxel update shared by the cpu backend and kernels/tsdf_integrate.cl; GLSL twin in
 * shaders/fvp_tsdf.glsl.
 *
 * Each item is one voxel of a brick to update: its centre is projected into the view's ROI
 * depth image (nearest pixel), and where that pixel holds a depth the projective distance
 * along the viewing ray, truncated, is averaged into the voxel with weight 1 / z^2, which
 * drops linearly to 0 from one voxel behind the surface to the truncation distance. Every
 * voxel is written by exactly one item, so the result does not depend on scheduling.
 * Floats throughout, rounded the same on every device: no contraction, and division and
 * square root correctly rounded by fvp_exact.h (a GPU's own are not), so every backend
 * gives the cpu backend's voxels bit for bit (tests/tsdf, docs/kernels.md). */
#ifndef FVP_TSDF_H
#define FVP_TSDF_H

#include "fvp_exact.h"
#include "fvp_map.h"

typedef struct fvp_tsdf_params {
  /* Camera from grid: rows [r0 r1 r2 t] of T_camera_grid, where grid coordinates are
   * metres from the grid's voxel (0, 0, 0) corner (small numbers, so floats keep 0.5 mm). */
  float camera_from_grid[12];
  float voxel_size_m, truncation_m, max_weight;
  /* Intrinsics of the depth image as uploaded (a crop of the full image: cx, cy shifted). */
  float fx_px, fy_px, cx_px, cy_px;
  int width_px, height_px;
  unsigned int update_bricks;    /* bricks to update; items = update_bricks * 512 */
  unsigned int allocated_bricks; /* bricks in the layer (sizes of the channels) */
} fvp_tsdf_params;

/* Updates one voxel: item = index into update_bricks * 512 + voxel in the brick. depth_m:
 * z-depth per pixel, 0 where the pixel is not ROI or has no valid depth. */
FVP_FN void fvp_tsdf_update_voxel(const fvp_tsdf_params* p, FVP_GLOBAL const int* brick_coords,
                                  FVP_GLOBAL const unsigned int* update_bricks, unsigned int item,
                                  FVP_GLOBAL const float* depth_m, FVP_GLOBAL float* tsdf_distance,
                                  FVP_GLOBAL float* tsdf_weight) {
  const unsigned int brick = update_bricks[item / FVP_BRICK_VOXELS];
  const unsigned int in_brick = item % FVP_BRICK_VOXELS;
  const unsigned int slot = brick * FVP_BRICK_VOXELS + in_brick;
  const float gx =
      ((float)(brick_coords[3 * brick + 0] * FVP_BRICK_EDGE + (int)(in_brick & 7u)) + 0.5f) *
      p->voxel_size_m;
  const float gy =
      ((float)(brick_coords[3 * brick + 1] * FVP_BRICK_EDGE + (int)((in_brick >> 3) & 7u)) + 0.5f) *
      p->voxel_size_m;
  const float gz =
      ((float)(brick_coords[3 * brick + 2] * FVP_BRICK_EDGE + (int)(in_brick >> 6)) + 0.5f) *
      p->voxel_size_m;
  const float* m = p->camera_from_grid;
  const float x = m[0] * gx + m[1] * gy + m[2] * gz + m[3];
  const float y = m[4] * gx + m[5] * gy + m[6] * gz + m[7];
  const float z = m[8] * gx + m[9] * gy + m[10] * gz + m[11];
  float u_f, v_f, depth, sdf, w, tsdf, w_old;
  int u, v;
  if (!(z > 0.0f)) return;
  u_f = FVP_FLOORF(fvp_div_rn(p->fx_px * x, z) + p->cx_px + 0.5f);
  v_f = FVP_FLOORF(fvp_div_rn(p->fy_px * y, z) + p->cy_px + 0.5f);
  if (!(u_f >= 0.0f && v_f >= 0.0f && u_f < (float)p->width_px && v_f < (float)p->height_px))
    return;
  u = (int)u_f;
  v = (int)v_f;
  depth = depth_m[v * p->width_px + u];
  if (!(depth > 0.0f)) return; /* not ROI, no depth, or NaN */
  /* Projective distance along the viewing ray, in metres. */
  sdf = fvp_div_rn((depth - z) * fvp_sqrt_rn(x * x + y * y + z * z), z);
  if (sdf < -p->truncation_m) return;
  w = fvp_div_rn(1.0f, z * z);
  if (sdf < -p->voxel_size_m)
    w = w * fvp_div_rn(p->truncation_m + sdf, p->truncation_m - p->voxel_size_m);
  if (!(w > 0.0f)) return;
  tsdf = sdf < p->truncation_m ? sdf : p->truncation_m;
  w_old = tsdf_weight[slot];
  tsdf_distance[slot] = fvp_div_rn(tsdf_distance[slot] * w_old + tsdf * w, w_old + w);
  tsdf_weight[slot] = w_old + w < p->max_weight ? w_old + w : p->max_weight;
}

#endif /* FVP_TSDF_H */
