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
uint fvp_edt_term(FvpEdtParams p, int x, int y, int z, int k) {
  ivec3 n = ivec3(x, y, z);
  n[p.axis] += k;
  if (n.x < 0 || n.y < 0 || n.z < 0 || n.x >= p.map.grid.dim_x || n.y >= p.map.grid.dim_y ||
      n.z >= p.map.grid.dim_z)
    return FVP_EDT_FAR;
  int slot = fvp_slot(p.map, n.x, n.y, n.z);
  if (slot < 0) return FVP_EDT_FAR;
  uint v;
  if (p.axis == 0) {
    float r = roi[slot];
    if (fvp_is_nan(r) || !(r > 0.0)) return FVP_EDT_FAR;
    v = 0u;
  } else {
    v = sq_in[slot];
    if (v == FVP_EDT_FAR) return FVP_EDT_FAR;
  }
  return v + uint(k * k);
}

uint fvp_edt_pass_voxel(FvpEdtParams p, int x, int y, int z) {
  uint best = fvp_edt_term(p, x, y, z, 0);
  for (int d = 1; d <= p.radius_vox && uint(d * d) < best; ++d) {
    best = min(best, fvp_edt_term(p, x, y, z, -d));
    best = min(best, fvp_edt_term(p, x, y, z, d));
  }
  return best;
}

void fvp_roi_distance_slot(FvpEdtParams p, uint slot) {
  int x, y, z;
  fvp_slot_voxel(slot, x, y, z);
  uint best = fvp_edt_pass_voxel(p, x, y, z);
  if (p.axis < 2) sq_out[slot] = best;
  else distance_vox[slot] = fvp_edt_distance_vox(best, p.radius_vox);
}
#endif

#if defined(FVP_HAS_BRICK_TABLE) && defined(FVP_HAS_OCCUPANCY) && defined(FVP_HAS_ROI) && \
    defined(FVP_HAS_FRONTIERS) && defined(FVP_HAS_COUNT) && !defined(FVP_FRONTIER_GLSL)
#define FVP_FRONTIER_GLSL
bool fvp_voxel_unknown(FvpBrickedGrid m, int x, int y, int z) {
  int slot = fvp_slot(m, x, y, z);
  if (slot < 0) return true;
  return fvp_is_nan(occupancy[slot]);
}

uint fvp_frontier_voxel(FvpFrontierParams p, int x, int y, int z, out ivec3 normal) {
  normal = ivec3(0);
  if (!fvp_in_map(p.map, x, y, z)) return 0u;
  int slot = fvp_slot(p.map, x, y, z);
  if (slot < 0) return 0u;
  float occ = occupancy[slot];
  if (fvp_is_nan(occ)) return 0u;  // unknown voxels are not frontiers
  float roi_value = roi[slot];
  bool is_roi = !fvp_is_nan(roi_value) && roi_value > 0.0;
  bool is_free = !(occ > p.occupied_logodds);
  if (!is_roi && !is_free) return 0u;
  bool face_unknown = false;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        int manhattan = int(dx != 0) + int(dy != 0) + int(dz != 0);
        if (manhattan == 0 || !fvp_in_map(p.map, x + dx, y + dy, z + dz)) continue;
        if (!fvp_voxel_unknown(p.map, x + dx, y + dy, z + dz)) continue;
        if (manhattan == 1) face_unknown = true;
        normal -= ivec3(dx, dy, dz);
      }
  if (!face_unknown) {
    normal = ivec3(0);
    return 0u;
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
