// fvp_map_kernels.glsl: GLSL twin of kernels/fvp_map_kernels.h, one function of the same
// name for each C function there; the C versions' buffer pointers are the shader's storage
// buffers of the same names. Include after fvp_map.glsl for the types; include again after
// declaring the buffers and defining FVP_HAS_<BUFFER> for each, for the functions over them.
#include "fvp_exact.glsl"
#ifndef FVP_MAP_KERNELS_GLSL
#define FVP_MAP_KERNELS_GLSL

const uint FVP_POINT_HIT = 1u;
const uint FVP_POINT_ROI = 2u;
const uint FVP_MARK_FREE = 1u;
const uint FVP_MARK_HIT = 2u;
const uint FVP_MARK_ROI = 4u;
const uint FVP_FRONTIER_ROI = 1u;
const uint FVP_FRONTIER_EXPLORE = 2u;
const uint FVP_EDT_FAR = 0x7fffffffu;
const uint FVP_UPDATE_CHUNK = 64u;

struct FvpScanPoint {
  float x_m, y_m, z_m;
  uint flags;
};

struct FvpScanParams {
  FvpBrickedGrid map;
  float sensor_x_m, sensor_y_m, sensor_z_m;
  uint point_count;
  uint slot_count;
  int brick_count;
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
  int axis;
  uint work_brick_count;
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

float fvp_edt_distance_vox(uint sq, int radius_vox) {
  if (sq >= uint(radius_vox * radius_vox)) return float(radius_vox);
  return fvp_sqrt_rn(float(sq));
}

#endif  // FVP_MAP_KERNELS_GLSL

#if defined(FVP_HAS_MARKS) && !defined(FVP_MARK_GLSL)
#define FVP_MARK_GLSL
void fvp_mark(int slot, uint bits) {
  uint word = uint(slot) >> 2;
  uint lane_bits = bits << (8u * (uint(slot) & 3u));
  if ((marks[word] & lane_bits) != lane_bits) atomicOr(marks[word], lane_bits);
}
#endif

#if defined(FVP_HAS_BRICK_TABLE) && defined(FVP_HAS_MARKS) && defined(FVP_HAS_MISSING) && \
    !defined(FVP_SCAN_MARK_GLSL)
#define FVP_SCAN_MARK_GLSL
void fvp_scan_mark_point(FvpScanParams p, FvpScanPoint pt) {
  FvpWalk w;
  if (fvp_walk_init(w, p.map, vec3(p.sensor_x_m, p.sensor_y_m, p.sensor_z_m),
                    vec3(pt.x_m, pt.y_m, pt.z_m)) != 0u)
    return;
  for (;;) {
    int axis = fvp_dda_next_axis(w.d);
    bool last = axis < 0;
    if (fvp_walk_mapped(w, p.map)) {
      if (w.entry < 0) {
        missing[w.brick] = 1u;
        missing[p.brick_count] = 1u;
      } else if (!last) {
        fvp_mark(fvp_walk_slot(w), FVP_MARK_FREE);
      } else if ((pt.flags & FVP_POINT_HIT) != 0u) {
        fvp_mark(fvp_walk_slot(w), (pt.flags & FVP_POINT_ROI) != 0u
                                       ? (FVP_MARK_HIT | FVP_MARK_ROI)
                                       : FVP_MARK_HIT);
      }
    }
    if (last || !fvp_walk_step(w, p.map, axis)) return;
  }
}
#endif

#if defined(FVP_HAS_MARKS) && defined(FVP_HAS_OCCUPANCY) && defined(FVP_HAS_ROI) && \
    !defined(FVP_SCAN_UPDATE_GLSL)
#define FVP_SCAN_UPDATE_GLSL
uint fvp_scan_update_chunk(FvpUpdateParams p, uint first) {
  uint updated = 0u;
  for (uint w = first >> 2; w < (first + FVP_UPDATE_CHUNK) >> 2; ++w) {
    uint word = marks[w];
    if (word == 0u) continue;
    for (uint lane = 0u; lane < 4u; ++lane) {
      uint m = (word >> (8u * lane)) & 0xffu;
      uint s = w * 4u + lane;
      if ((m & FVP_MARK_HIT) != 0u) {
        occupancy[s] = fvp_logodds_update(occupancy[s], p.hit_logodds, p.clamp_min_logodds,
                                          p.clamp_max_logodds);
        if (p.has_roi != 0)
          roi[s] = fvp_logodds_update(roi[s],
                                      (m & FVP_MARK_ROI) != 0u ? p.hit_logodds : p.miss_logodds,
                                      p.clamp_min_logodds, p.clamp_max_logodds);
        ++updated;
      } else if ((m & FVP_MARK_FREE) != 0u) {
        occupancy[s] = fvp_logodds_update(occupancy[s], p.miss_logodds, p.clamp_min_logodds,
                                          p.clamp_max_logodds);
        ++updated;
      }
    }
    marks[w] = 0u;
  }
  return updated;
}
#endif

#if defined(FVP_SCAN_UPDATE_GLSL) && defined(FVP_HAS_UPDATED) && defined(FVP_HAS_CHANGED_BRICKS) && \
    !defined(FVP_SCAN_UPDATE_ITEM_GLSL)
#define FVP_SCAN_UPDATE_ITEM_GLSL
void fvp_scan_update_item(FvpUpdateParams p, uint item) {
  uint first = item * FVP_UPDATE_CHUNK;
  uint n = fvp_scan_update_chunk(p, first);
  if (n == 0u) return;
  atomicAdd(updated[0], n);
  changed_bricks[first / uint(FVP_BRICK_VOXELS)] = 1u;
}
#endif

#if defined(FVP_HAS_BRICK_TABLE) && defined(FVP_HAS_ROI) && defined(FVP_HAS_SQ_IN) && \
    defined(FVP_HAS_BRICK_COORDS) && defined(FVP_HAS_SQ_OUT) && defined(FVP_HAS_DISTANCE_VOX) && \
    !defined(FVP_EDT_GLSL)
#define FVP_EDT_GLSL
// fvp_map_kernels.h's twin: one line of 8 voxels of a work brick along the pass's axis, each
// source voxel of the window read once and relaxing every output it reaches.
uint fvp_edt_source(FvpEdtParams p, int slot) {
  if (p.axis == 0) {
    float r = roi[slot];
    return (fvp_is_nan(r) || !(r > 0.0)) ? FVP_EDT_FAR : 0u;
  }
  return sq_in[slot];
}

void fvp_roi_distance_line(FvpEdtParams p, uint item) {
  uint brick = work_bricks[item / uint(FVP_BRICK_LINES)], line = item % uint(FVP_BRICK_LINES);
  int axis = p.axis, radius = p.radius_vox;
  int reach = (radius + FVP_BRICK_EDGE - 1) / FVP_BRICK_EDGE;
  ivec3 c = ivec3(brick_coords[3 * brick + 0], brick_coords[3 * brick + 1],
                  brick_coords[3 * brick + 2]);
  ivec3 first_local = ivec3(axis == 0 ? 0 : int(line & 7u),
                            axis == 1 ? 0 : (axis == 0 ? int(line & 7u) : int(line >> 3)),
                            axis == 2 ? 0 : int(line >> 3));
  int stride = axis == 0 ? 1 : (axis == 1 ? FVP_BRICK_EDGE : FVP_BRICK_EDGE * FVP_BRICK_EDGE);
  int in_brick0 = fvp_local_of(first_local.x, first_local.y, first_local.z);
  int bricks_along = axis == 0 ? p.map.bricks_x : (axis == 1 ? p.map.bricks_y : p.map.bricks_z);
  uint best[FVP_BRICK_EDGE];
  for (int j = 0; j < FVP_BRICK_EDGE; ++j) best[j] = FVP_EDT_FAR;
  for (int nb = -reach; nb <= reach; ++nb) {
    ivec3 n = c;
    n[axis] += nb;
    if (n[axis] < 0 || n[axis] >= bricks_along) continue;
    int entry = brick_table[n.x + p.map.bricks_x * (n.y + p.map.bricks_y * n.z)];
    if (entry < 0) continue;
    for (int t = 0; t < FVP_BRICK_EDGE; ++t) {
      int s = nb * FVP_BRICK_EDGE + t;
      if (s < -radius || s > FVP_BRICK_EDGE - 1 + radius) continue;
      uint v = fvp_edt_source(p, fvp_slot_of_entry(entry, in_brick0 + t * stride));
      if (v == FVP_EDT_FAR) continue;
      for (int j = 0; j < FVP_BRICK_EDGE; ++j) {
        int k = s - j;
        if (k < -radius || k > radius) continue;
        best[j] = min(best[j], v + uint(k * k));
      }
    }
  }
  for (int j = 0; j < FVP_BRICK_EDGE; ++j) {
    int slot = int(brick) * FVP_BRICK_VOXELS + in_brick0 + j * stride;
    if (axis < 2) sq_out[slot] = best[j];
    else distance_vox[slot] = fvp_edt_distance_vox(best[j], radius);
  }
}
#endif

#if defined(FVP_HAS_BRICK_TABLE) && defined(FVP_HAS_OCCUPANCY) && defined(FVP_HAS_ROI) && \
    defined(FVP_HAS_FRONTIERS) && defined(FVP_HAS_COUNT) && !defined(FVP_FRONTIER_GLSL)
#define FVP_FRONTIER_GLSL
// fvp_map_kernels.h's twin: -1 outside the mapped region, 1 unknown, 0 known.
int fvp_neighbour_unknown(FvpBrickedGrid m, int own_brick, int own_entry, int nx, int ny, int nz) {
  if (nx < 0 || ny < 0 || nz < 0 || nx >= m.grid.dim_x || ny >= m.grid.dim_y ||
      nz >= m.grid.dim_z)
    return -1;
  int brick = fvp_brick_of(m, nx, ny, nz);
  int entry = brick == own_brick ? own_entry : brick_table[brick];
  if (m.use_region != 0 && !(entry >= 0 && (entry & FVP_BRICK_INSIDE) != 0) &&
      !fvp_region_contains(m.region, nx, ny, nz))
    return -1;
  if (entry < 0) return 1;
  return fvp_is_nan(occupancy[fvp_slot_of_entry(entry, fvp_local_of(nx, ny, nz))]) ? 1 : 0;
}

uint fvp_frontier_voxel(FvpFrontierParams p, int x, int y, int z, out ivec3 normal) {
  normal = ivec3(0);
  if (!fvp_in_map(p.map, x, y, z)) return 0u;
  int own_brick = fvp_brick_of(p.map, x, y, z);
  int own_entry = brick_table[own_brick];
  if (own_entry < 0) return 0u;
  int slot = fvp_slot_of_entry(own_entry, fvp_local_of(x, y, z));
  float occ = occupancy[slot];
  if (fvp_is_nan(occ)) return 0u;  // unknown voxels are not frontiers
  float roi_value = roi[slot];
  bool is_roi = !fvp_is_nan(roi_value) && roi_value > 0.0;
  bool is_free = !(occ > p.occupied_logodds);
  if (!is_roi && !is_free) return 0u;
  // fvp_map_kernels.h's order: the 6 faces settle most voxels, then the 26 make the normal.
  bool face_unknown = false;
  for (int a = 0; a < 6 && !face_unknown; ++a) {
    ivec3 n = ivec3(x, y, z);
    n[a >> 1] += (a & 1) != 0 ? 1 : -1;
    face_unknown = fvp_neighbour_unknown(p.map, own_brick, own_entry, n.x, n.y, n.z) == 1;
  }
  if (!face_unknown) return 0u;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if ((dx == 0 && dy == 0 && dz == 0) ||
            fvp_neighbour_unknown(p.map, own_brick, own_entry, x + dx, y + dy, z + dz) != 1)
          continue;
        normal -= ivec3(dx, dy, dz);
      }
  return (is_roi ? FVP_FRONTIER_ROI : 0u) | (is_free ? FVP_FRONTIER_EXPLORE : 0u);
}

void fvp_frontier_append(FvpFrontierParams p, int x, int y, int z) {
  ivec3 normal;
  uint flags = fvp_frontier_voxel(p, x, y, z, normal);
  if (flags == 0u) return;
  uint index = atomicAdd(count[0], 1u);
  if (index < p.capacity)
    frontiers[index] = FvpFrontier(x, y, z, flags, normal.x, normal.y, normal.z, 0);
}
#endif
