// fvp_tsdf.glsl: GLSL twin of kernels/fvp_tsdf.h, one function of the same name for each C
// function there; the C versions' buffer pointers are the shader's storage buffers of the
// same names. Include once for the types; include again after declaring the buffers and
// defining FVP_HAS_TSDF_BUFFERS, for the functions over them.
#include "fvp_exact.glsl"
#ifndef FVP_TSDF_GLSL
#define FVP_TSDF_GLSL

struct FvpTsdfParams {
  float camera_from_grid[12];
  float voxel_size_m, truncation_m, max_weight;
  float fx_px, fy_px, cx_px, cy_px;
  int width_px, height_px;
  uint update_bricks;
  uint allocated_bricks;
};

#endif  // FVP_TSDF_GLSL

#if defined(FVP_HAS_TSDF_BUFFERS) && !defined(FVP_TSDF_UPDATE_GLSL)
#define FVP_TSDF_UPDATE_GLSL

// `precise` keeps the compiler from fusing multiply-adds, as the OpenCL side's
// FP_CONTRACT OFF and the C side's plain arithmetic do; every operand handed to fvp_div_rn or
// fvp_sqrt_rn is a precise variable, so it is rounded before the call as in C.
void fvp_tsdf_update_voxel(FvpTsdfParams p, uint item) {
  uint brick = update_bricks[item / uint(FVP_BRICK_VOXELS)];
  uint in_brick = item % uint(FVP_BRICK_VOXELS);
  uint slot = brick * uint(FVP_BRICK_VOXELS) + in_brick;
  precise float gx =
      (float(brick_coords[3 * brick + 0] * FVP_BRICK_EDGE + int(in_brick & 7u)) + 0.5) *
      p.voxel_size_m;
  precise float gy =
      (float(brick_coords[3 * brick + 1] * FVP_BRICK_EDGE + int((in_brick >> 3) & 7u)) + 0.5) *
      p.voxel_size_m;
  precise float gz =
      (float(brick_coords[3 * brick + 2] * FVP_BRICK_EDGE + int(in_brick >> 6)) + 0.5) *
      p.voxel_size_m;
  precise float x = p.camera_from_grid[0] * gx + p.camera_from_grid[1] * gy +
                    p.camera_from_grid[2] * gz + p.camera_from_grid[3];
  precise float y = p.camera_from_grid[4] * gx + p.camera_from_grid[5] * gy +
                    p.camera_from_grid[6] * gz + p.camera_from_grid[7];
  precise float z = p.camera_from_grid[8] * gx + p.camera_from_grid[9] * gy +
                    p.camera_from_grid[10] * gz + p.camera_from_grid[11];
  if (!(z > 0.0)) return;
  precise float fx_x = p.fx_px * x;
  precise float u_f = floor(fvp_div_rn(fx_x, z) + p.cx_px + 0.5);
  precise float fy_y = p.fy_px * y;
  precise float v_f = floor(fvp_div_rn(fy_y, z) + p.cy_px + 0.5);
  if (!(u_f >= 0.0 && v_f >= 0.0 && u_f < float(p.width_px) && v_f < float(p.height_px))) return;
  int u = int(u_f);
  int v = int(v_f);
  float depth = depth_m[v * p.width_px + u];
  if (!(depth > 0.0)) return;
  precise float range_sq = x * x + y * y + z * z;
  precise float along = (depth - z) * fvp_sqrt_rn(range_sq);
  precise float sdf = fvp_div_rn(along, z);
  if (sdf < -p.truncation_m) return;
  precise float z_sq = z * z;
  precise float w = fvp_div_rn(1.0, z_sq);
  if (sdf < -p.voxel_size_m) {
    precise float ramp_top = p.truncation_m + sdf;
    precise float ramp_len = p.truncation_m - p.voxel_size_m;
    w = w * fvp_div_rn(ramp_top, ramp_len);
  }
  if (!(w > 0.0)) return;
  float tsdf = sdf < p.truncation_m ? sdf : p.truncation_m;
  float w_old = tsdf_weight[slot];
  precise float d_sum = tsdf_distance[slot] * w_old + tsdf * w;
  precise float w_sum = w_old + w;
  precise float d_new = fvp_div_rn(d_sum, w_sum);
  tsdf_distance[slot] = d_new;
  tsdf_weight[slot] = w_old + w < p.max_weight ? w_old + w : p.max_weight;
}

#endif  // FVP_TSDF_UPDATE_GLSL
