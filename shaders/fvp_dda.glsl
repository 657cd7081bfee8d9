// fvp_dda.glsl: GLSL twin of kernels/fvp_dda.h (exact fixed-point voxel traversal).
// Same algorithm, same integer arithmetic, same tie rules; the cross-backend tests
// check it visits exactly what the C reference visits. Read fvp_dda.h for the why.
// Needs: #extension GL_ARB_gpu_shader_int64 (device feature shaderInt64).

#ifndef FVP_DDA_GLSL
#define FVP_DDA_GLSL

#define FVP_DDA_FRACTION_BITS 16
const int64_t FVP_DDA_ONE = 65536l;
const float FVP_DDA_MAX_ABS_FIXED = 536870912.0;

const uint FVP_RAY_REACHED_END = 0u;
const uint FVP_RAY_HIT_OCCUPIED = 1u;
const uint FVP_RAY_LEFT_GRID = 2u;
const uint FVP_RAY_INVALID = 3u;

// Mirrors fvp_grid_params (all 4-byte scalars: identical std430 / push-constant layout).
struct FvpGridParams {
  int dim_x, dim_y, dim_z;
  float origin_x_m, origin_y_m, origin_z_m;
  float voxel_size_m;
  float fixed_per_m;
};

struct FvpRay {
  vec4 origin_m;
  vec4 end_m;
};

struct FvpRayResult {
  uint steps;
  float field_sum;
  int stop_voxel;
  uint status;
};

struct FvpTraverseParams {
  FvpGridParams grid;
  float occupied_threshold;
  uint ray_count;
};

struct FvpDda {
  ivec3 key;
  ivec3 step;
  ivec3 remaining;
  int64_t step_len[3];
  int64_t cross_xy, cross_xz, cross_yz;
};

// NaN and infinity tests on the bits: Vulkan lets compilers assume float operands are not
// NaN, so isnan() and comparisons cannot be trusted to see them.
bool fvp_is_nan(float v) { return (floatBitsToUint(v) & 0x7fffffffu) > 0x7f800000u; }
bool fvp_is_finite(float v) { return (floatBitsToUint(v) & 0x7f800000u) != 0x7f800000u; }

int64_t fvp_floor_div_one(int64_t v) {
  return v >= 0l ? v / FVP_DDA_ONE : -((-v + FVP_DDA_ONE - 1l) / FVP_DDA_ONE);
}

bool fvp_dda_quantize(float p_m, float origin_m, float fixed_per_m, out int64_t q_fixed) {
  q_fixed = 0l;
  if (!fvp_is_finite(p_m)) return false;
  precise float q = (p_m - origin_m) * fixed_per_m;
  if (!fvp_is_finite(q) || !(q > -FVP_DDA_MAX_ABS_FIXED && q < FVP_DDA_MAX_ABS_FIXED)) return false;
  q_fixed = int64_t(floor(q));
  return true;
}

int64_t fvp_dda_crossings_before(int64_t dist, int64_t len, int64_t num, int64_t den,
                                 bool tie_before) {
  int64_t r = num * len - dist * den;
  int64_t unit = FVP_DDA_ONE * den;
  if (tie_before) return r >= 0l ? r / unit + 1l : 0l;
  return r > 0l ? (r - 1l) / unit + 1l : 0l;
}

void fvp_dda_set_cross_terms(inout FvpDda d, int64_t dist[3]) {
  int64_t lx = d.step_len[0] / FVP_DDA_ONE, ly = d.step_len[1] / FVP_DDA_ONE,
          lz = d.step_len[2] / FVP_DDA_ONE;
  d.cross_xy = dist[0] * ly - dist[1] * lx;
  d.cross_xz = dist[0] * lz - dist[2] * lx;
  d.cross_yz = dist[1] * lz - dist[2] * ly;
}

uint fvp_dda_init(inout FvpDda d, FvpGridParams g, vec3 o_m, vec3 e_m) {
  int64_t o[3], e[3], dist[3], len[3];
  vec3 origin_m = vec3(g.origin_x_m, g.origin_y_m, g.origin_z_m);
  ivec3 dim = ivec3(g.dim_x, g.dim_y, g.dim_z);
  for (int a = 0; a < 3; ++a) {
    if (!fvp_dda_quantize(o_m[a], origin_m[a], g.fixed_per_m, o[a]) ||
        !fvp_dda_quantize(e_m[a], origin_m[a], g.fixed_per_m, e[a]))
      return FVP_RAY_INVALID;
  }
  for (int a = 0; a < 3; ++a) {
    int64_t k0 = fvp_floor_div_one(o[a]);
    int64_t k1 = fvp_floor_div_one(e[a]);
    d.key[a] = int(k0);
    if (e[a] > o[a]) {
      d.step[a] = 1;
      len[a] = e[a] - o[a];
      dist[a] = (k0 + 1l) * FVP_DDA_ONE - o[a];
      d.remaining[a] = int(k1 - k0);
    } else if (e[a] < o[a]) {
      d.step[a] = -1;
      len[a] = o[a] - e[a];
      dist[a] = o[a] - k0 * FVP_DDA_ONE;
      d.remaining[a] = int(k0 - k1);
    } else {
      d.step[a] = 0;
      len[a] = 0l;
      dist[a] = FVP_DDA_ONE;
      d.remaining[a] = 0;
    }
    d.step_len[a] = FVP_DDA_ONE * len[a];
  }

  int entry_axis = -1;
  int64_t entry_num = 0l, entry_den = 1l;
  for (int a = 0; a < 3; ++a) {
    int64_t needed;
    if (d.key[a] < 0) {
      if (d.step[a] <= 0) return FVP_RAY_LEFT_GRID;
      needed = -int64_t(d.key[a]);
    } else if (d.key[a] >= dim[a]) {
      if (d.step[a] >= 0) return FVP_RAY_LEFT_GRID;
      needed = int64_t(d.key[a]) - int64_t(dim[a] - 1);
    } else {
      continue;
    }
    if (needed > int64_t(d.remaining[a])) return FVP_RAY_LEFT_GRID;
    int64_t num = dist[a] + (needed - 1l) * FVP_DDA_ONE;
    if (entry_axis < 0 || num * entry_den > entry_num * len[a]) {
      entry_axis = a;
      entry_num = num;
      entry_den = len[a];
    }
  }
  if (entry_axis >= 0) {
    for (int a = 0; a < 3; ++a) {
      int64_t n;
      if (a == entry_axis) {
        n = (d.key[a] < 0) ? -int64_t(d.key[a]) : int64_t(d.key[a]) - int64_t(dim[a] - 1);
      } else {
        n = fvp_dda_crossings_before(dist[a], len[a], entry_num, entry_den, a > entry_axis);
        if (n > int64_t(d.remaining[a])) n = int64_t(d.remaining[a]);
      }
      d.key[a] += d.step[a] * int(n);
      d.remaining[a] -= int(n);
      dist[a] += n * FVP_DDA_ONE;
    }
    for (int a = 0; a < 3; ++a)
      if (d.key[a] < 0 || d.key[a] >= dim[a]) return FVP_RAY_LEFT_GRID;
  }
  fvp_dda_set_cross_terms(d, dist);
  return 0u;
}

int fvp_dda_next_axis(FvpDda d) {
  bool done_x = d.remaining.x == 0, done_y = d.remaining.y == 0, done_z = d.remaining.z == 0;
  if (done_x && done_y && done_z) return -1;
  bool x_first_y = !done_x && (done_y || d.cross_xy < 0l);
  bool x_first_z = !done_x && (done_z || d.cross_xz < 0l);
  bool y_first_z = !done_y && (done_z || d.cross_yz < 0l);
  return x_first_y ? (x_first_z ? 0 : 2) : (y_first_z ? 1 : 2);
}

void fvp_dda_advance(inout FvpDda d, int axis) {
  d.key[axis] += d.step[axis];
  d.remaining[axis] -= 1;
  if (axis == 0) {
    d.cross_xy += d.step_len[1];
    d.cross_xz += d.step_len[2];
  } else if (axis == 1) {
    d.cross_xy -= d.step_len[0];
    d.cross_yz += d.step_len[2];
  } else {
    d.cross_xz -= d.step_len[0];
    d.cross_yz -= d.step_len[1];
  }
}

#endif  // FVP_DDA_GLSL

// Functions over buffers: the C versions take them as pointers, the shaders declare them as
// storage buffers of the same names. A shader includes this file once for the types, then
// declares its buffers, defines FVP_HAS_<buffers> and includes it again for the functions.

// Needs the buffers `occupancy` and `field` (dense grid, float each).
#if defined(FVP_HAS_DENSE_GRID) && !defined(FVP_DDA_DENSE_GLSL)
#define FVP_DDA_DENSE_GLSL
FvpRayResult fvp_traverse_ray(FvpGridParams g, float occupied_threshold, vec3 origin_m,
                              vec3 end_m) {
  FvpRayResult r = FvpRayResult(0u, 0.0, -1, 0u);
  FvpDda d;
  r.status = fvp_dda_init(d, g, origin_m, end_m);
  if (r.status != 0u) return r;
  ivec3 dim = ivec3(g.dim_x, g.dim_y, g.dim_z);
  ivec3 stride = ivec3(1, g.dim_x, g.dim_x * g.dim_y);
  int index = d.key.x + stride.y * d.key.y + stride.z * d.key.z;
  for (;;) {
    r.steps += 1u;
    r.field_sum += field[index];
    if (occupancy[index] >= occupied_threshold) {
      r.status = FVP_RAY_HIT_OCCUPIED;
      r.stop_voxel = index;
      return r;
    }
    int axis = fvp_dda_next_axis(d);
    if (axis < 0) {
      r.status = FVP_RAY_REACHED_END;
      r.stop_voxel = index;
      return r;
    }
    fvp_dda_advance(d, axis);
    if (d.key[axis] < 0 || d.key[axis] >= dim[axis]) {
      r.status = FVP_RAY_LEFT_GRID;
      return r;
    }
    index += d.step[axis] * stride[axis];
  }
  return r;
}
#endif
