// fvp_map.glsl: GLSL twin of kernels/fvp_map.h (region test, log-odds update, brick
// layout, the bricked walker). Include after fvp_dda.glsl; include again after declaring
// the `brick_table` buffer (and defining FVP_HAS_BRICK_TABLE) for the functions reading it.
#ifndef FVP_MAP_GLSL
#define FVP_MAP_GLSL

const int FVP_BRICK_SHIFT = 3;
const int FVP_BRICK_EDGE = 8;
const int FVP_BRICK_VOXELS = 512;
const int FVP_BRICK_LINES = 64;
const int FVP_BRICK_INSIDE = 0x40000000;
const int FVP_BRICK_INDEX_MASK = 0x3fffffff;
const int FVP_NO_BRICK = -1;

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

int fvp_slot_of_entry(int entry, int in_brick) {
  return (entry & FVP_BRICK_INDEX_MASK) * FVP_BRICK_VOXELS + in_brick;
}

bool fvp_in_map(FvpBrickedGrid m, int x, int y, int z) {
  if (x < 0 || y < 0 || z < 0 || x >= m.grid.dim_x || y >= m.grid.dim_y || z >= m.grid.dim_z)
    return false;
  return m.use_region == 0 || fvp_region_contains(m.region, x, y, z);
}

struct FvpWalk {
  FvpDda d;
  int brick;
  int entry;
  int in_brick;
};

int fvp_walk_slot(FvpWalk w) { return fvp_slot_of_entry(w.entry, w.in_brick); }

bool fvp_walk_mapped(FvpWalk w, FvpBrickedGrid m) {
  return m.use_region == 0 || (w.entry >= 0 && (w.entry & FVP_BRICK_INSIDE) != 0) ||
         fvp_region_contains(m.region, w.d.key.x, w.d.key.y, w.d.key.z);
}

#endif  // FVP_MAP_GLSL

#if defined(FVP_HAS_BRICK_TABLE) && !defined(FVP_MAP_TABLE_GLSL)
#define FVP_MAP_TABLE_GLSL
int fvp_slot(FvpBrickedGrid m, int x, int y, int z) {
  int entry = brick_table[fvp_brick_of(m, x, y, z)];
  if (entry < 0) return -1;
  return fvp_slot_of_entry(entry, fvp_local_of(x, y, z));
}

uint fvp_walk_init(inout FvpWalk w, FvpBrickedGrid m, vec3 o_m, vec3 e_m) {
  uint status = fvp_dda_init(w.d, m.grid, o_m, e_m);
  if (status != 0u) return status;
  w.brick = fvp_brick_of(m, w.d.key.x, w.d.key.y, w.d.key.z);
  w.entry = brick_table[w.brick];
  w.in_brick = fvp_local_of(w.d.key.x, w.d.key.y, w.d.key.z);
  return 0u;
}

bool fvp_walk_step(inout FvpWalk w, FvpBrickedGrid m, int axis) {
  int dim = axis == 0 ? m.grid.dim_x : (axis == 1 ? m.grid.dim_y : m.grid.dim_z);
  int brick_stride = axis == 0 ? 1 : (axis == 1 ? m.bricks_x : m.bricks_x * m.bricks_y);
  int local_stride = axis == 0 ? 1 : (axis == 1 ? 8 : 64);
  fvp_dda_advance(w.d, axis);
  int key = w.d.key[axis];
  if (key < 0 || key >= dim) return false;
  if ((key & 7) == (w.d.step[axis] > 0 ? 0 : 7)) {
    w.brick += w.d.step[axis] * brick_stride;
    w.entry = brick_table[w.brick];
    w.in_brick -= w.d.step[axis] * 7 * local_stride;
  } else {
    w.in_brick += w.d.step[axis] * local_stride;
  }
  return true;
}
#endif

#if defined(FVP_HAS_BRICK_COORDS) && !defined(FVP_MAP_COORDS_GLSL)
#define FVP_MAP_COORDS_GLSL
void fvp_slot_voxel(uint slot, out int x, out int y, out int z) {
  uint brick = slot / 512u, in_brick = slot % 512u;
  x = brick_coords[3 * brick + 0] * FVP_BRICK_EDGE + int(in_brick & 7u);
  y = brick_coords[3 * brick + 1] * FVP_BRICK_EDGE + int((in_brick >> 3) & 7u);
  z = brick_coords[3 * brick + 2] * FVP_BRICK_EDGE + int(in_brick >> 6);
}
#endif
