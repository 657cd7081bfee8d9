// C++ view of the plain structs that cross the host/device boundary. They are defined
// once, in kernels/fvp_dda.h, which the OpenCL kernels include too; the GLSL shaders
// mirror them. The asserts pin the layouts the shaders rely on.
#pragma once

#include <array>
#include <cstdint>

extern "C" {
#include "fvp_dda.h"
}

namespace fvp::accel {

using GridParams = fvp_grid_params;
using Ray = fvp_ray;
using RayResult = fvp_ray_result;
using TraverseParams = fvp_traverse_params;

static_assert(sizeof(GridParams) == 32, "must match FvpGridParams in shaders/fvp_dda.glsl");
static_assert(sizeof(Ray) == 32, "must match FvpRay (two vec4)");
static_assert(sizeof(RayResult) == 16, "must match FvpRayResult");
static_assert(sizeof(TraverseParams) == 40, "must match the ray_traverse push constants");

/// Geometry of a dense grid whose voxel (0,0,0) has its lower corner at origin_m.
/// Throws std::invalid_argument for non-positive sizes or a grid of 2^31 voxels or more.
GridParams makeGridParams(std::array<int, 3> dims, std::array<float, 3> origin_m,
                          float voxel_size_m);

inline std::int64_t voxelCount(const GridParams& g) {
  return std::int64_t{g.dim_x} * g.dim_y * g.dim_z;
}

inline Ray makeRay(std::array<float, 3> origin_m, std::array<float, 3> end_m) {
  return Ray{{origin_m[0], origin_m[1], origin_m[2], 0.0f}, {end_m[0], end_m[1], end_m[2], 0.0f}};
}

}  // namespace fvp::accel
