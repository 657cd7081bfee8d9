// An Embree 3 scene over the occupied voxels of a map grid, answering first-hit and
// occlusion queries (terminate information-gain rays at the first occluder, cull candidate
// views whose line of sight is blocked; docs/design.md section 4).
//
// Geometry: one Embree quad mesh per 8x8x8 brick holding the exposed faces of the brick's
// occupied voxels (faces between two occupied voxels are left out; each face belongs to
// exactly one occupied voxel, so a hit names its voxel exactly). Voxel (i, j, k) covers
// [origin + i * size, origin + (i + 1) * size) per axis with origin and size the grid's
// kernel view (GridGeometry::params()), the boxes the DDA of kernels/fvp_dda.h walks.
// Kept current as scans arrive: setOccupied() marks the bricks whose faces change, commit()
// rebuilds only those and recommits the scene (a dynamic, robust scene: Embree keeps the
// other bricks' geometry and rebuilds its two-level BVH over them).
//
// Queries are const and may run concurrently from several threads after commit(); edits
// and commit() must not overlap queries. Every Embree call is checked; a failure throws
// accel::BackendError naming the call, file, line and Embree's message.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "fvp/accel/kernel_types.h"
#include "fvp/host/map/grid_geometry.h"

namespace fvp::host::map {

struct VoxelHit {
  std::array<int, 3> voxel{};  ///< grid index of the occupied voxel hit
  float t = 0.0f;              ///< ray parameter of the hit (origin + t * direction)
  Eigen::Vector3f point_m = Eigen::Vector3f::Zero();  ///< hit point on the voxel's face
};

class OccupiedVoxelScene {
 public:
  explicit OccupiedVoxelScene(const GridGeometry& grid);
  /// The scene over `occupied` (grid indices), committed.
  OccupiedVoxelScene(const GridGeometry& grid, const std::vector<std::array<int, 3>>& occupied);
  ~OccupiedVoxelScene();
  OccupiedVoxelScene(const OccupiedVoxelScene&) = delete;
  OccupiedVoxelScene& operator=(const OccupiedVoxelScene&) = delete;
  OccupiedVoxelScene(OccupiedVoxelScene&&) noexcept;
  OccupiedVoxelScene& operator=(OccupiedVoxelScene&&) noexcept;

  const GridGeometry& grid() const;

  /// Sets one voxel; takes effect at the next commit(). Throws std::out_of_range outside
  /// the grid. setOccupiedUnchecked skips the bounds check (the caller guarantees it).
  void setOccupied(const std::array<int, 3>& index, bool occupied);
  void setOccupiedUnchecked(const std::array<int, 3>& index, bool occupied);
  bool isOccupied(const std::array<int, 3>& index) const;
  /// Clears every voxel, then sets `occupied` (takes effect at the next commit()).
  void assignOccupied(const std::vector<std::array<int, 3>>& occupied);

  /// Rebuilds the geometry of the bricks whose exposed faces changed since the last commit
  /// and commits the scene. Returns the number of bricks rebuilt.
  std::size_t commit();
  bool hasPendingChanges() const;

  std::size_t occupiedCount() const;
  std::size_t brickGeometryCount() const;  ///< Embree geometries (bricks with faces)
  std::size_t faceCount() const;           ///< exposed faces (quads) in the scene

  /// First occupied voxel along origin + t * direction, t in [t_min, t_max] (direction need
  /// not be normalised; t is in its units). nullopt when nothing is hit or direction is 0.
  std::optional<VoxelHit> firstHit(const Eigen::Vector3f& origin_m,
                                   const Eigen::Vector3f& direction, float t_min = 0.0f,
                                   float t_max = std::numeric_limits<float>::infinity()) const;
  /// First hit on each segment origin_m -> end_m (t in [0, 1]), 16 rays per Embree packet.
  std::vector<std::optional<VoxelHit>> firstHits(const std::vector<accel::Ray>& segments) const;

  /// True when the segment origin -> end touches an occupied voxel (t in [0, 1]).
  bool occluded(const Eigen::Vector3f& origin_m, const Eigen::Vector3f& end_m) const;
  /// occluded() for each segment (1 / 0), 16 rays per Embree packet.
  std::vector<std::uint8_t> occludedBatch(const std::vector<accel::Ray>& segments) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fvp::host::map
