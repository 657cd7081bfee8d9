// The coarse + fine map pair behind one interface, with two engines of identical semantics:
// "grid" (flat bricked storage the compute kernels read; default for FVP) and "octomap"
// (octomap::OcTree coarse + an ROI octree fine; the papers' reference, default for RVP).
//
// Semantics (OctoMap's, docs/design.md section 5): log-odds hit/miss with clamping; occupied
// when p > occupied_prob; unknown = never updated. One scan updates each voxel once: the
// union of voxels crossed by the rays, minus the end-point voxels, is free; end-point
// voxels are hits. ROI (fine map only): a second log-odds per voxel, a hit where any ROI
// point ends, a miss where only other points end. Rays update the fine map only inside
// the Cluster Region sphere (voxel centres within the radius).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <string_view>
#include <vector>

#include "fvp/host/core/cluster_region.h"
#include "fvp/host/core/labeled_clouds.h"
#include "fvp/host/map/brick_change_log.h"
#include "fvp/host/map/frontier_voxel.h"
#include "fvp/host/map/grid_geometry.h"
#include "fvp/host/map/map_config.h"
#include "fvp/host/map/occupied_voxel_scene.h"
#include "fvp/host/map/scan_points.h"
#include "fvp/host/map/scan_stats.h"
#include "fvp/host/map/voxel_state.h"

namespace fvp::accel {
class Backend;
}
namespace octomap {
class OcTree;
}

namespace fvp::host::map {

enum class MapLevel { kCoarse, kFine };

class MapEngine {
 public:
  virtual ~MapEngine();
  MapEngine(const MapEngine&) = delete;
  MapEngine& operator=(const MapEngine&) = delete;

  /// "grid" or "octomap".
  virtual std::string_view engineName() const = 0;
  const MapConfig& config() const { return config_; }
  const ClusterRegion& region() const { return region_; }
  /// Scans integrated so far.
  std::size_t scanCount() const { return scans_; }

  /// Moves the fine map to another Cluster Region (the next cluster of a run over a tree):
  /// the fine map starts empty over the new region, the coarse map keeps everything seen,
  /// so the arm's collision world and the planners' coarse reads carry over. Throws
  /// std::invalid_argument for a region without a finite centre and a positive radius.
  void moveToRegion(const ClusterRegion& region);

  /// Integrates one view: rays from clouds.sensor_origin_m to every point (world frame),
  /// cut and counted by prepareScanPoints (scan_points.h), the same for both engines.
  ScanStats integrate(const LabeledClouds& clouds);

  // Const reads (coarseClass, fineState, roiDistance_m, ...) may run on several threads at
  // once (the planner's snapshot reads every fine voxel in parallel); nothing may change the
  // map meanwhile.

  /// State of the coarse voxel containing p (unknown outside the observation box).
  virtual VoxelClass coarseClass(const Eigen::Vector3d& p_m) const = 0;
  /// State of the fine voxel containing p (unknown outside the Cluster Region).
  virtual VoxelState fineState(const Eigen::Vector3d& p_m) const = 0;

  /// Coarse map as an OctoMap binary tree (.bt) that OctoMap's tools read.
  virtual void exportCoarse(const std::filesystem::path& bt_path) const = 0;
  /// Fine map as an OctoMap .ot file (occupancy + ROI; format in docs/maps.md).
  virtual void exportFine(const std::filesystem::path& ot_path) const = 0;

  /// The map's voxel lattice (the same for both engines).
  virtual const GridGeometry& gridGeometry(MapLevel level) const = 0;
  /// Grid indices of the occupied voxels of one map.
  virtual std::vector<std::array<int, 3>> occupiedVoxels(MapLevel level) const = 0;

  /// Embree scene over the occupied voxels of one map for first-hit and occlusion queries,
  /// current with every scan integrated so far: after new scans, the next call rebuilds
  /// only the bricks whose voxels changed.
  const OccupiedVoxelScene& occupiedScene(MapLevel level);

  /// The bricks (8^3 voxels, brick_change_log.h) of one map whose voxels' class, ROI or
  /// (fine map) d_i as of the last updateRoiDistance() may differ from what they were at
  /// cursor `since`, so that a copy derived from the map (the planner's gain snapshot) is
  /// updated rather than rebuilt. `all` for a cursor of another map or Cluster Region, or
  /// the default cursor. Pass the returned `now` next time.
  BrickChanges changesSince(MapLevel level, const ChangeCursor& since);

  // ---- Reads the planner needs, with the same results on both engines ----

  /// Paper Eq. 1's d_i over the fine grid: Euclidean distance between voxel centres to the
  /// nearest known ROI voxel (ROI log-odds > 0), in metres, capped at max_d_m. Recomputes
  /// when scans arrived or the cap changed since the last call; otherwise free.
  virtual void updateRoiDistance(double max_d_m) = 0;
  /// d_i of one fine voxel as of the last updateRoiDistance(); the cap outside the fine
  /// grid. Throws std::logic_error before the first updateRoiDistance().
  virtual double roiDistance_m(const std::array<int, 3>& fine_index) const = 0;
  /// ROI and exploration frontiers of the fine map (frontier_voxel.h), sorted by grid index
  /// (z, then y, then x).
  virtual std::vector<FrontierVoxel> frontiers() = 0;
  /// The coarse map as an octomap::OcTree at the coarse resolution (the FCL collision
  /// world, as MoveIt's occupancy map monitor uses), current with every scan so far.
  virtual const octomap::OcTree& coarseOcTree() = 0;

 protected:
  MapEngine(const MapConfig& config, const ClusterRegion& region)
      : config_(config), region_(region) {}
  /// Applies one view's prepared points; sets the voxel counts of stats.
  virtual void integrateScan(const Eigen::Vector3d& sensor_origin_m,
                             const std::vector<accel::ScanPoint>& points, ScanStats& stats) = 0;
  /// Brings `scene` up to date with the scans integrated so far (fresh: it is new and
  /// empty). The default sets every occupied voxel (occupiedVoxels()); engines that know
  /// which parts changed update only those.
  virtual void refreshScene(MapLevel level, OccupiedVoxelScene& scene, bool fresh);
  /// Builds an empty fine map (and what derives from it) over region().
  virtual void placeFineMap() = 0;
  /// Where engines record what integrateScan and updateRoiDistance changed (a brick of
  /// voxels that may not have changed may be recorded; one that did must be).
  BrickChangeLog& changeLog(MapLevel level);
  /// Brings the change logs up to date before changesSince() reads them, for engines that
  /// track changes elsewhere first (the grid engine's brick stamps).
  virtual void syncChangeLogs() {}
  /// Whether the engine records its changes in changeLog(). An engine that does not (a
  /// program's own) gets `all` from changesSince(): a stale copy is never kept.
  virtual bool recordsBrickChanges() const { return false; }

 private:
  struct SceneState {
    std::unique_ptr<OccupiedVoxelScene> scene;
    std::size_t synced_scans = 0;
  };
  MapConfig config_;
  ClusterRegion region_;
  std::size_t scans_ = 0;
  SceneState scenes_[2];
  BrickChangeLog change_logs_[2];  ///< coarse, fine; placed on first use
};

/// Throws std::invalid_argument unless engine is registered (map_engine_registry.h) and has
/// a backend if it needs one: what createMapEngine checks, for callers that create the
/// engine later (MappingSession).
void checkMapEngineChoice(std::string_view engine, const accel::Backend* backend);

/// An engine by its registered name: "grid" (needs a compute backend), "octomap" (backend
/// ignored, may be null), or one a program added. Throws std::invalid_argument for an
/// unknown engine name or a bad config.
std::unique_ptr<MapEngine> createMapEngine(std::string_view engine, const MapConfig& config,
                                           const ClusterRegion& region, accel::Backend* backend);

}  // namespace fvp::host::map
