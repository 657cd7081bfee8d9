// Reproducible ray-traversal workloads: a canopy-like dense grid (free space around the
// cluster, unknown beyond, occupied fruitlet shells and leaf plates) and random rays.
// Shared by the tests, the benchmarks and `fvp traverse`, so all three measure one thing.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "fvp/accel/backend.h"

namespace fvp::accel {

// Log-odds values of OctoMap's default sensor model (hit 0.7, miss 0.4).
inline constexpr float kHitLogOdds = 0.8472979f;    // log(0.7 / 0.3)
inline constexpr float kMissLogOdds = -0.4054651f;  // log(0.4 / 0.6)
/// Occupied means p > 0.5; unknown voxels hold 0, so the walk uses a small positive bar.
inline constexpr float kDefaultOccupiedThreshold = 0.5f;

struct DenseGrid {
  GridParams params{};
  std::vector<float> occupancy;  ///< log-odds, 0 = unknown
  std::vector<float> field;      ///< per-voxel float summed along rays (in [0.5, 1])
};

/// A cube of side dims voxels centred on the world origin, voxel_size_m each. Voxels
/// within 0.45 * side of the centre are known (free or occupied), the rest unknown.
DenseGrid makeCanopyGrid(int side_voxels, float voxel_size_m, std::uint64_t seed);

struct RayOptions {
  std::size_t count = 10000;
  /// Fraction of rays whose origin lies outside the grid (a camera looking in).
  float outside_fraction = 0.0f;
};

/// Rays with uniformly random ends inside the grid; origins inside or outside.
std::vector<Ray> makeRandomRays(const GridParams& grid, const RayOptions& options,
                                std::uint64_t seed);

/// Upload, dispatch and download on one backend (the explicit sequence spelled out once).
std::vector<RayResult> traverseOnBackend(Backend& backend, const DenseGrid& grid,
                                         const std::vector<Ray>& rays,
                                         float occupied_threshold = kDefaultOccupiedThreshold);

/// Sum of RayResult::steps: the voxel steps a batch performed.
std::uint64_t totalSteps(const std::vector<RayResult>& results);

}  // namespace fvp::accel
