// C++ view of the plain structs that cross the host/device boundary. They are defined
// once, in kernels/fvp_dda.h, which the OpenCL kernels include too; the GLSL shaders
// mirror them. The asserts pin the layouts the shaders rely on.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

extern "C" {
#include "fvp_dda.h"
#include "fvp_info_gain.h"
#include "fvp_map_kernels.h"
#include "fvp_stereo.h"
#include "fvp_tsdf.h"
}

namespace fvp::accel {

using GridParams = fvp_grid_params;
using Ray = fvp_ray;
using RayResult = fvp_ray_result;
using TraverseParams = fvp_traverse_params;

// Map kernels (kernels/fvp_map_kernels.h).
using ScanPoint = fvp_scan_point;
using BrickedGridParams = fvp_bricked_grid;
using ScanParams = fvp_scan_params;
using UpdateParams = fvp_update_params;
using EdtParams = fvp_edt_params;
using FrontierParams = fvp_frontier_params;
using Frontier = fvp_frontier;

// Information gain (kernels/fvp_info_gain.h).
using GainParams = fvp_gain_params;
using GainSegment = fvp_gain_segment;
using GainResultRaw = fvp_gain_result;

// Projective TSDF integration (kernels/fvp_tsdf.h).
using TsdfParams = fvp_tsdf_params;

// Coarse-guided semi-global matching (kernels/fvp_stereo.h).
using StereoParams = fvp_stereo_params;

inline constexpr int kBrickEdge = FVP_BRICK_EDGE;
inline constexpr int kBrickVoxels = FVP_BRICK_VOXELS;
inline constexpr int kNoBrick = FVP_NO_BRICK;

static_assert(sizeof(ScanPoint) == 16, "must match FvpScanPoint");
static_assert(sizeof(BrickedGridParams) == 64, "must match FvpBrickedGrid");
static_assert(sizeof(ScanParams) == 88, "must match FvpScanParams");
static_assert(sizeof(UpdateParams) == 24, "must match FvpUpdateParams");
static_assert(sizeof(EdtParams) == 80, "must match FvpEdtParams");
static_assert(sizeof(FrontierParams) == 76, "must match FvpFrontierParams");
static_assert(sizeof(Frontier) == 32, "must match FvpFrontier");
static_assert(sizeof(GainParams) == 68, "must match FvpGainParams");
static_assert(sizeof(GainSegment) == 48, "must match FvpGainSegment (three vec4)");
static_assert(sizeof(GainResultRaw) == 16, "must match FvpGainResult");
static_assert(sizeof(TsdfParams) == 92, "must match FvpTsdfParams");
static_assert(sizeof(StereoParams) == 68, "must match FvpStereoParams");
static_assert(sizeof(GridParams) == 32, "must match FvpGridParams in shaders/fvp_dda.glsl");
static_assert(sizeof(Ray) == 32, "must match FvpRay (two vec4)");
static_assert(sizeof(RayResult) == 16, "must match FvpRayResult");
static_assert(sizeof(TraverseParams) == 40, "must match FvpTraverseParams");

/// Geometry of a dense grid whose voxel (0,0,0) has its lower corner at origin_m.
/// Throws std::invalid_argument for non-positive sizes or more than 16384 voxels per axis.
GridParams makeGridParams(std::array<int, 3> dims, std::array<float, 3> origin_m,
                          float voxel_size_m);

/// Bricks in the grid's brick table.
inline std::size_t brickCount(const BrickedGridParams& m) {
  return static_cast<std::size_t>(m.bricks_x) * m.bricks_y * m.bricks_z;
}

/// Throws std::invalid_argument (naming `what`) unless the grid is a whole number of bricks.
inline void checkBrickedGrid(const BrickedGridParams& m, const char* what) {
  if (m.bricks_x <= 0 || m.bricks_y <= 0 || m.bricks_z <= 0 ||
      m.grid.dim_x != m.bricks_x * kBrickEdge || m.grid.dim_y != m.bricks_y * kBrickEdge ||
      m.grid.dim_z != m.bricks_z * kBrickEdge)
    throw std::invalid_argument(std::string(what) + ": grid dims must be 8 x the brick dims");
}

/// Throws std::invalid_argument (naming `what`) unless slot_count is whole bricks of slots.
inline void checkSlotCount(std::uint32_t slot_count, const char* what) {
  if (slot_count % kBrickVoxels != 0)
    throw std::invalid_argument(std::string(what) + ": slot_count must be a multiple of 512");
}

inline std::int64_t voxelCount(const GridParams& g) {
  return std::int64_t{g.dim_x} * g.dim_y * g.dim_z;
}

/// 32-bit words of the gain snapshot's fine codes (2 bytes per voxel) and coarse
/// occupancy (1 byte per voxel) for grids of these geometries (kernels/fvp_info_gain.h).
inline std::size_t gainFineWords(const GridParams& g) {
  return static_cast<std::size_t>((voxelCount(g) + 1) / 2);
}
inline std::size_t gainCoarseWords(const GridParams& g) {
  return static_cast<std::size_t>((voxelCount(g) + 3) / 4);
}

inline Ray makeRay(std::array<float, 3> origin_m, std::array<float, 3> end_m) {
  return Ray{{origin_m[0], origin_m[1], origin_m[2], 0.0f}, {end_m[0], end_m[1], end_m[2], 0.0f}};
}

}  // namespace fvp::accel
