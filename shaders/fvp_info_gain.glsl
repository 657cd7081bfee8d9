// fvp_info_gain.glsl: GLSL twin of kernels/fvp_info_gain.h, one function of the same name for
// each C function there; the C versions' buffer pointers are the shader's storage buffers
// of the same names. Include once for the types; include again after declaring the buffers
// and defining FVP_HAS_FINE_CODES and FVP_HAS_COARSE_OCCUPIED, for the functions over them.
#ifndef FVP_INFO_GAIN_GLSL
#define FVP_INFO_GAIN_GLSL

const uint FVP_GAIN_IN_REGION = 0x8000u;
const uint FVP_GAIN_OCCUPIED = 0x4000u;
const uint FVP_GAIN_WEIGHT_MASK = 0x3FFFu;

struct FvpGainSegment {
  vec4 origin_m;  // w: 1 = walk the coarse map to the entry first
  vec4 entry_m;
  vec4 end_m;
};

struct FvpGainResult {
  uint weight_sum;
  uint region_voxels;
  uint voxel_steps;
  uint blocked;
};

struct FvpGainParams {
  FvpGridParams fine;
  FvpGridParams coarse;
  uint segment_count;
};

#endif  // FVP_INFO_GAIN_GLSL

#if defined(FVP_HAS_FINE_CODES) && defined(FVP_HAS_COARSE_OCCUPIED) && \
    !defined(FVP_INFO_GAIN_WALK_GLSL)
#define FVP_INFO_GAIN_WALK_GLSL

uint fvp_gain_fine_code(int i) {
  return (fine_codes[i >> 1] >> (uint(i & 1) * 16u)) & 0xFFFFu;
}

uint fvp_gain_coarse_occupied(int i) {
  return (coarse_occupied[i >> 2] >> (uint(i & 3) * 8u)) & 0xFFu;
}

FvpGainResult fvp_gain_walk(FvpGainParams p, vec3 origin_m, vec3 entry_m, vec3 end_m,
                            bool walk_coarse) {
  FvpGainResult r = FvpGainResult(0u, 0u, 0u, 0u);
  FvpDda d;
  if (walk_coarse && fvp_dda_init(d, p.coarse, origin_m, entry_m) == 0u) {
    ivec3 dim = ivec3(p.coarse.dim_x, p.coarse.dim_y, p.coarse.dim_z);
    for (;;) {
      r.voxel_steps += 1u;
      if (fvp_gain_coarse_occupied(d.key.x + dim.x * (d.key.y + dim.y * d.key.z)) != 0u) {
        r.blocked = 1u;
        return r;
      }
      int axis = fvp_dda_next_axis(d);
      if (axis < 0) break;
      fvp_dda_advance(d, axis);
      if (d.key[axis] < 0 || d.key[axis] >= dim[axis]) break;
    }
  }
  if (fvp_dda_init(d, p.fine, entry_m, end_m) == 0u) {
    ivec3 dim = ivec3(p.fine.dim_x, p.fine.dim_y, p.fine.dim_z);
    for (;;) {
      r.voxel_steps += 1u;
      uint code = fvp_gain_fine_code(d.key.x + dim.x * (d.key.y + dim.y * d.key.z));
      if ((code & FVP_GAIN_IN_REGION) != 0u) {
        r.region_voxels += 1u;
        if ((code & FVP_GAIN_OCCUPIED) != 0u) return r;
        r.weight_sum += code & FVP_GAIN_WEIGHT_MASK;
      }
      int axis = fvp_dda_next_axis(d);
      if (axis < 0) break;
      fvp_dda_advance(d, axis);
      if (d.key[axis] < 0 || d.key[axis] >= dim[axis]) break;
    }
  }
  return r;
}

#endif  // FVP_INFO_GAIN_WALK_GLSL
