// Information gain of viewpoint candidates (paper Eq. 1-2, docs/design.md section 6) over a
// compact read-only snapshot of the maps, refreshed once per planning iteration:
// 2 bytes per fine voxel (in-region bit, occupied bit, Eq. 1 weight quantised to 1/8192)
// and 1 byte per coarse voxel (occupied), instead of the maps' 8-byte integration voxels,
// because the gain walks are memory bound.
//
// A refresh rewrites only the 8^3-voxel bricks the map reports changed since the last one
// (MapEngine::changesSince: the bricks a scan touched, and on the fine map those whose d_i
// moved) and uploads only the words those bricks occupy; a different map, region or grid
// rebuilds it whole. Both paths compute every voxel's code with the same function, so an
// updated snapshot equals a fresh build byte for byte (tests/planner/snapshot_refresh_test).
//
// One ray from the camera centre to the target. The coarse map is walked from the camera to
// where the ray enters the Cluster Region sphere: an occupied coarse voxel there blocks the
// view (IG 0, N_c 0). Inside, the fine map is walked to the target voxel: every voxel inside
// the region counts in N_c; unknown ones add Eq. 1's weight of their distance to the
// nearest known ROI, known ones 0; the walk stops at the first occupied voxel (counted) or
// the target. IG = sum of weights / N_c, 0 when N_c = 0. Frustum mode (our extension):
// rays_x x rays_y rays through pixel-grid directions over the field of view, each ending at
// the target's depth, IG the mean of the per-ray IGs. Walks use the exact fixed-point DDA
// of kernels/fvp_dda.h, so they visit the same voxels as every map kernel.
//
// The walks are the info_gain kernel (kernels/fvp_info_gain.h): the host splits every ray at
// the region sphere in double precision, the kernel walks and returns integers, and the
// host turns them into gains, so every backend gives bit-identical results. Without a
// backend the same C walk runs here directly (OpenMP over rays).
//
// Embree culling (embree_cull): before the walks, each ray's coarse part (camera -> region
// entry) is tested against the Embree scene of the coarse map's occupied voxels; rays it
// finds blocked are not walked (gain 0, blocked). The kernel would stop at the same voxel
// anyway, so culling saves the coarse walk of blocked rays and the transfer of their
// segments; it costs one Embree occlusion query per ray. Embree tests the voxels' faces,
// the DDA their lattice: they can disagree on rays that graze a voxel's edge.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "fvp/accel/kernel_types.h"
#include "fvp/host/map/brick_change_log.h"
#include "fvp/host/map/grid_geometry.h"

namespace fvp::accel {
class Backend;
class DeviceBuffer;
}  // namespace fvp::accel

namespace fvp::host::map {
class MapEngine;
class OccupiedVoxelScene;
}  // namespace fvp::host::map

namespace fvp::host::planner {

enum class GainMode { kSingleRay, kFrustum };
/// "single_ray" or "frustum" (planner configs' gain_mode); throws std::invalid_argument.
GainMode parseGainMode(std::string_view name);

// The simulated camera: 1440 x 1080 px at fx = fy = 1100 px.
inline constexpr double kDefaultFovXRad = 1.1632;  // 2 atan(720 / 1100)
inline constexpr double kDefaultFovYRad = 0.9130;  // 2 atan(540 / 1100)

struct InfoGainConfig {
  double max_d_m = 0.02;  ///< Eq. 1 max_d
  GainMode mode = GainMode::kSingleRay;
  int frustum_rays_x = 16, frustum_rays_y = 12;
  double fov_x_rad = kDefaultFovXRad, fov_y_rad = kDefaultFovYRad;
  bool embree_cull = false;  ///< test rays' coarse parts with Embree before the walks
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

struct ViewQuery {
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  Eigen::Vector3d target_m = Eigen::Vector3d::Zero();
};

/// What one evaluate() did (rays, Embree culling, walks), for reports and benchmarks.
struct EvaluateStats {
  std::size_t rays = 0;    ///< rays that enter the region (segments to walk or cull)
  std::size_t culled = 0;  ///< of which Embree found blocked before the region
  std::size_t walked = 0;  ///< rays the walk kernel ran
  double cull_s = 0.0;     ///< wall time of the Embree queries
  double walk_s = 0.0;     ///< wall time of the walks (with transfers)
};

/// What the last InfoGainEvaluator::refresh() did, for reports and benchmarks.
struct SnapshotRefreshStats {
  bool full = true;               ///< rebuilt whole (first refresh, another map or region)
  std::size_t fine_bricks = 0;    ///< fine bricks rewritten (all of them when full)
  std::size_t coarse_bricks = 0;  ///< coarse bricks rewritten
  std::size_t upload_bytes = 0;   ///< bytes sent to the backend's device (0 without one)
  std::size_t upload_ranges = 0;  ///< byte ranges they were sent in (one transfer per map)
  double distance_s = 0.0;        ///< wall time of the map's ROI distance update
  double snapshot_s = 0.0;        ///< wall time of the snapshot itself (codes + upload)
};

struct GainResult {
  double ig = 0.0;
  std::uint32_t region_voxels = 0;  ///< N_c (summed over rays in frustum mode)
  std::uint64_t voxel_steps = 0;    ///< coarse + fine voxels visited
  bool blocked = false;             ///< single ray: an occupied coarse voxel before the region
};

class InfoGainEvaluator {
 public:
  /// backend: where the walks run (any of cpu, opencl, vulkan); null walks here directly.
  explicit InfoGainEvaluator(const InfoGainConfig& config, accel::Backend* backend = nullptr);
  ~InfoGainEvaluator();
  InfoGainEvaluator(InfoGainEvaluator&&) noexcept;
  InfoGainEvaluator& operator=(InfoGainEvaluator&&) noexcept;
  const InfoGainConfig& config() const { return config_; }

  /// After each integration: the ROI distance field (map.updateRoiDistance(max_d_m)) and
  /// the snapshot, updated from the bricks that changed since the last refresh of the same
  /// map. Returns the wall time it took, seconds.
  double refresh(map::MapEngine& map);
  const SnapshotRefreshStats& lastRefresh() const { return last_refresh_; }
  /// The snapshot in the kernel's layout (kernels/fvp_info_gain.h): fine codes and coarse
  /// occupancy, 32-bit words, dense over each grid, x fastest.
  std::span<const std::uint32_t> fineWords() const { return fine_words_; }
  std::span<const std::uint32_t> coarseWords() const { return coarse_words_; }
  /// The same as the backend's device holds them (downloaded); empty without a backend.
  std::vector<std::uint32_t> deviceFineWords() const;
  std::vector<std::uint32_t> deviceCoarseWords() const;
  /// IG of every query (the same result for any backend and thread count).
  /// Throws std::logic_error before the first refresh(). With embree_cull, the map given
  /// to refresh() must outlive the calls (its coarse Embree scene is queried).
  std::vector<GainResult> evaluate(std::span<const ViewQuery> queries,
                                   EvaluateStats* stats = nullptr) const;
  /// IG of one ray segment origin -> end (the per-ray step of both modes).
  GainResult evaluateRay(const Eigen::Vector3d& origin_m, const Eigen::Vector3d& end_m) const;
  std::size_t snapshotBytes() const;
  /// What one segment crosses, for gains other than Eq. 1-2 (RVP): the coarse map outside
  /// the region, the fine map inside; region voxels and the unknown ones among them, up to
  /// the first occupied voxel (then occluded; that voxel is not counted).
  struct RayCensus {
    std::uint32_t region_voxels = 0, unknown_voxels = 0;
    bool occluded = false;
    std::uint64_t voxel_steps = 0;
  };
  RayCensus census(const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m) const;
  /// The fraction of a sphere's near side a camera at camera_m would see: 19 rays to points
  /// spread over its silhouette disc, each ending two fine voxels short of the surface (the
  /// sphere's own voxels do not hide it), blocked by the first occupied voxel (census).
  /// Unknown space does not block: optimistic, as every gain here. 0 from inside the sphere.
  double visibleFraction(const Eigen::Vector3d& camera_m, const Eigen::Vector3d& center_m,
                         double radius_m) const;
  /// Whether any occupied coarse voxel lies within radius_m of p (voxel centres): a camera
  /// body there would collide, so the motion planner need not be asked.
  bool occupiedWithin(const Eigen::Vector3d& p_m, double radius_m) const;
  /// Scans the snapshot was built from (MapEngine::scanCount at the last refresh).
  std::size_t snapshotScans() const { return snapshot_scans_; }
  double fineVoxelSize_m() const { return fine_.voxel_size_m; }

  /// Where the walks run: the backend's name (e.g. "vulkan"), or "host" without one.
  const char* walkDevice() const;

  // Snapshot codes of a fine voxel (kernels/fvp_info_gain.h).
  static constexpr std::uint16_t kInRegion = 0x8000;
  static constexpr std::uint16_t kOccupied = 0x4000;
  static constexpr std::uint16_t kWeightMask = 0x3FFF;
  static constexpr double kWeightScale = 8192.0;  ///< weight 1 = 8192

 private:
  /// The whole snapshot from the map; a new device copy.
  void rebuild(const map::MapEngine& map);
  /// Rewrites the given bricks (brick_change_log.h ids) of each grid and uploads the words
  /// they occupy.
  void updateBricks(const map::MapEngine& map, const std::vector<int>& fine_bricks,
                    const std::vector<int>& coarse_bricks);
  /// The snapshot code of one fine voxel (both paths use it: the same bits by construction).
  std::uint16_t computeFineCode(const map::MapEngine& map, const fvp_region& region,
                                const std::array<int, 3>& index) const;
  /// The info_gain kernel over segments (on the backend, or here without one).
  void walk(std::span<const accel::GainSegment> segments, accel::GainResultRaw* results) const;
  std::uint16_t fineCode(std::size_t i) const {
    return static_cast<std::uint16_t>(fine_words_[i >> 1] >> ((i & 1) * 16));
  }
  bool coarseOccupied(std::size_t i) const {
    return ((coarse_words_[i >> 2] >> ((i & 3) * 8)) & 0xFFu) != 0;
  }

  InfoGainConfig config_;
  accel::Backend* backend_ = nullptr;
  bool ready_ = false;
  std::size_t snapshot_scans_ = 0;
  map::GridGeometry fine_, coarse_;
  Eigen::Vector3d region_center_m_ = Eigen::Vector3d::Zero();
  double region_radius_m_ = 0.0;
  // The snapshot in the kernel's layout: 2 bytes per fine voxel and 1 byte per coarse voxel,
  // packed into 32-bit words; with a backend, also on its device.
  std::vector<std::uint32_t> fine_words_, coarse_words_;
  std::unique_ptr<accel::DeviceBuffer> fine_device_, coarse_device_;
  mutable std::unique_ptr<accel::DeviceBuffer> segment_device_, result_device_;
  const map::OccupiedVoxelScene* coarse_scene_ = nullptr;  ///< embree_cull only
  // Where the snapshot stands in each map's change log (map::MapEngine::changesSince).
  map::ChangeCursor fine_cursor_, coarse_cursor_;
  SnapshotRefreshStats last_refresh_;
};

/// Eq. 1: the weight of an unknown voxel at distance d_m from the nearest known ROI.
inline double roiProximityWeight(double d_m, double max_d_m) {
  return d_m < max_d_m ? 0.5 + 0.5 * (max_d_m - d_m) / max_d_m : 0.5;
}

}  // namespace fvp::host::planner
