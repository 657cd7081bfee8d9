// fvp_map.glsl: GLSL twin of kernels/fvp_map.h and the shared parts of
// kernels/fvp_map_kernels.h (structs, region test, log-odds update, brick layout).
// Include after fvp_dda.glsl.
#ifndef FVP_MAP_GLSL
#define FVP_MAP_GLSL

const int FVP_BRICK_SHIFT = 3;
const int FVP_BRICK_EDGE = 8;
const int FVP_BRICK_VOXELS = 512;
const int FVP_BRICK_INSIDE = 0x40000000;
const int FVP_BRICK_INDEX_MASK = 0x3fffffff;

const uint FVP_POINT_HIT = 1u;
const uint FVP_POINT_ROI = 2u;
const uint FVP_FRONTIER_ROI = 1u;
const uint FVP_FRONTIER_EXPLORE = 2u;
const uint FVP_EDT_FAR = 0x7fffffffu;

// Packed scan marks (Vulkan only): one byte lane per slot in a uint word, set with
// atomicOr because GLSL has no portable byte stores.
const uint FVP_MARK_FREE = 1u;
const uint FVP_MARK_HIT = 2u;
const uint FVP_MARK_ROI = 4u;

struct FvpRegion {
  float center_x_vox, center_y_vox, center_z_vox;
  float radius_sq_vox;
};

struct FvpBrickedGrid {
  FvpGridParams grid;
  int bricks_x, bricks_y, bricks_z;
  int use_region;
  FvpRegion region;
};

struct FvpScanPoint {
  float x_m, y_m, z_m;
  uint flags;
};

struct FvpScanParams {
  FvpBrickedGrid map;
  float sensor_x_m, sensor_y_m, sensor_z_m;
  uint point_count;
};

struct FvpUpdateParams {
  uint slot_count;
  float hit_logodds, miss_logodds, clamp_min_logodds, clamp_max_logodds;
  int has_roi;
};

struct FvpEdtParams {
  FvpBrickedGrid map;
  int radius_vox;
  uint slot_count;
};

struct FvpFrontierParams {
  FvpBrickedGrid map;
  float occupied_logodds;
  uint slot_count;
  uint capacity;
};

struct FvpFrontier {
  int x, y, z;
  uint flags;
  int normal_x, normal_y, normal_z;
  int pad;
};

bool fvp_region_contains(FvpRegion r, int x, int y, int z) {
  precise float dx = (float(x) + 0.5) - r.center_x_vox;
  precise float dy = (float(y) + 0.5) - r.center_y_vox;
  precise float dz = (float(z) + 0.5) - r.center_z_vox;
  precise float d2 = dx * dx;
  d2 = d2 + dy * dy;
  d2 = d2 + dz * dz;
  return d2 <= r.radius_sq_vox;
}

float fvp_logodds_update(float value, float delta, float clamp_min, float clamp_max) {
  precise float v = fvp_is_nan(value) ? 0.0 : value;
  v = v + delta;
  if (v < clamp_min) v = clamp_min;
  if (v > clamp_max) v = clamp_max;
  return v;
}

int fvp_brick_of(FvpBrickedGrid m, int x, int y, int z) {
  return (x >> FVP_BRICK_SHIFT) +
         m.bricks_x * ((y >> FVP_BRICK_SHIFT) + m.bricks_y * (z >> FVP_BRICK_SHIFT));
}

int fvp_local_of(int x, int y, int z) { return (x & 7) + 8 * ((y & 7) + 8 * (z & 7)); }

bool fvp_in_map(FvpBrickedGrid m, int x, int y, int z) {
  if (x < 0 || y < 0 || z < 0 || x >= m.grid.dim_x || y >= m.grid.dim_y || z >= m.grid.dim_z)
    return false;
  return m.use_region == 0 || fvp_region_contains(m.region, x, y, z);
}

float fvp_edt_distance_vox(uint sq, int radius_vox) {
  if (sq >= uint(radius_vox * radius_vox)) return float(radius_vox);
  return sqrt(float(sq));
}

#endif  // FVP_MAP_GLSL
