// The "octomap" map engine (docs/design.md section 5): the papers' reference. Coarse map: an
// octomap::OcTree at coarse_voxel_size_m over the observation box; fine map: a RoiOcTree
// (occupancy + ROI log-odds) at fine_voxel_size_m over the Cluster Region.
//
// One scan is integrated as OctoMap's insertPointCloud does (computeUpdate, then one
// updateNode per key): the keys of computeRayKeys(origin, end) of every ray form the free
// set, the end points' keys the occupied set, free minus occupied is updated as a miss and
// occupied as a hit, each key once. Differences from a plain insertPointCloud, all required
// by the map contract (map_engine.h):
// - Only voxels of the grids (coarseGridGeometry / fineGridGeometry lattices, OctoMap key =
//   lattice index + 32768) are updated; the fine map only voxels whose centre lies in the
//   Cluster Region (fvp_region_contains, the test the grid engine uses). OctoMap's own bbx
//   limit is not used: it drops every ray whose end point lies outside the box.
// - Each ray is first clipped to the map's box (and, fine, to the Cluster Region sphere),
//   grown by two voxels, so a 1 mm map walks only the voxels it may update. The clipped
//   segment lies on the same line, but computeRayKeys starts from the clipped point in
//   float, so crossings that nearly tie may be ordered differently: a voxel touched only at
//   a corner can differ. The grid engine agreement target is >= 99.9 %, not 100 %.
// - Points are prepared by prepareScanPoints (scan_points.h), as for the grid engine: NaN /
//   infinite points are skipped and counted; points beyond sensor_max_range_m are cut there
//   as OctoMap's maxrange does (free up to the cut, the cut voxel itself not updated, no
//   hit) and counted. The cut is computed in double and rounded to float, where OctoMap's
//   computeUpdate computes it in float: the end may differ in the last bits.
// - fine_map_extent observation_box (RVP's setting in the paper, one 1 mm ROI octree over
//   the whole observation space): the fine tree's rays are clipped to the observation box
//   as the coarse grid holds it (snapped outward to whole bricks) and to the region, and
//   every voxel of either is updated. Reads (fineState, frontiers, the ROI distance,
//   occupiedVoxels, the scene) still cover the Cluster Region sphere only; the rest is what
//   that map costs to keep, and it is exported with the tree.
// - ROI (fine map): +hit where any ROI point ends, +miss where only other points end,
//   unchanged in free voxels; clamped like occupancy.
//
// Voxel classes: classifyLogOdds (voxel_state.h), the grid engine's rule, on the nodes the
// tree has (unknown when it has none); ROI when ROI log-odds > 0.
#pragma once

#include <octomap/OcTree.h>

#include <array>
#include <memory>
#include <vector>

#include "fvp/host/map/grid_geometry.h"
#include "fvp/host/map/map_engine.h"
#include "fvp/host/map/roi_octree.h"

namespace fvp::host::map {

class OctomapMapEngine : public MapEngine {
 public:
  /// Throws std::invalid_argument for a bad config or grids outside OctoMap's key range.
  OctomapMapEngine(const MapConfig& config, const ClusterRegion& region);
  ~OctomapMapEngine() override;

  std::string_view engineName() const override { return "octomap"; }
  /// integrateScan and updateRoiDistance record their changes (a subclass that changes voxels
  /// elsewhere must mark them in changeLog() too).
  bool recordsBrickChanges() const override { return true; }

  const GridGeometry& gridGeometry(MapLevel level) const override {
    return level == MapLevel::kCoarse ? coarse_grid_ : fine_grid_;
  }
  std::vector<std::array<int, 3>> occupiedVoxels(MapLevel level) const override;

 protected:
  void integrateScan(const Eigen::Vector3d& sensor_origin_m,
                     const std::vector<accel::ScanPoint>& points, ScanStats& stats) override;
  void placeFineMap() override;

 public:
  VoxelClass coarseClass(const Eigen::Vector3d& p_m) const override;
  VoxelState fineState(const Eigen::Vector3d& p_m) const override;
  /// The same by grid index (coarseGrid() / fineGrid()); unknown outside the grid/region.
  VoxelClass coarseClassAt(const std::array<int, 3>& index) const;
  VoxelState fineStateAt(const std::array<int, 3>& index) const;

  /// .bt (octomap::OcTree) and .ot (ColorOcTree, ROI in the colour): octomap_io.h.
  void exportCoarse(const std::filesystem::path& bt_path) const override;
  void exportFine(const std::filesystem::path& ot_path) const override;

  // Planner reads (map_engine.h): the grid engine's definitions and results, except that
  // DynamicEDT overestimates a distance now and then (1e-6 to 1e-5 of the voxels, at most
  // 0.1 voxel measured; docs/maps.md).
  /// DynamicEDTOctomap (OctoMap's dynamicEDT3D) over the fine grid's box, on an OcTree
  /// holding the known ROI voxels as its only occupied voxels.
  void updateRoiDistance(double max_d_m) override;
  double roiDistance_m(const std::array<int, 3>& fine_index) const override;
  /// Visits the fine tree's leafs (the known voxels); neighbours are looked up in the tree.
  std::vector<FrontierVoxel> frontiers() override;
  const octomap::OcTree& coarseOcTree() override { return *coarse_; }

  const octomap::OcTree& coarseTree() const { return *coarse_; }
  const RoiOcTree& fineTree() const { return *fine_; }
  const GridGeometry& coarseGrid() const { return coarse_grid_; }
  const GridGeometry& fineGrid() const { return fine_grid_; }
  /// OctoMap key of a grid voxel (lattice index + the tree's key offset, 32768).
  octomap::OcTreeKey coarseKey(const std::array<int, 3>& index) const;
  octomap::OcTreeKey fineKey(const std::array<int, 3>& index) const;

 private:
  /// Records in the fine change log the voxels whose d_i differs from previous (the field
  /// before the last updateRoiDistance(); every brick when it had another size or cap).
  void recordDistanceChanges(const std::vector<float>& previous);

  GridGeometry coarse_grid_;
  GridGeometry fine_grid_;
  fvp_region fine_region_{};
  // Fine lattice indices of the observation box, [lo, hi) per axis (observation_box extent).
  std::array<std::int64_t, 3> fine_box_lo_{}, fine_box_hi_{};
  int key_offset_ = 0;  ///< OctoMap key of lattice index 0 (tree_max_val)
  std::unique_ptr<octomap::OcTree> coarse_;
  std::unique_ptr<RoiOcTree> fine_;
  // ROI distance in voxels over the fine grid box (x fastest) as of distance_scans_ scans
  // with cap distance_max_d_m_ (negative before the first updateRoiDistance()).
  std::vector<float> distance_vox_;
  double distance_max_d_m_ = -1.0;
  std::size_t distance_scans_ = 0;
};

}  // namespace fvp::host::map
