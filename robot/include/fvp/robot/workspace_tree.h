// The workspace tree (docs/design.md section 7, the paper's reachability filter): N random joint
// configurations (free of self and static collision) put their camera position and viewing
// direction into a counting grid of position cells x cube-map direction bins. A viewpoint is
// reachable when its cell and direction bin were hit at least workspace_min_count times.
// The slider only translates the UR5, so each configuration of the six arm joints counts at
// every slider position (the arm's grid swept along the travel): N samples of the arm give
// the density of N x (travel / resolution) samples of all seven joints. The grid's axes are
// the slider's (x along the travel, z up), its cells resolution_m() on an edge.
// Built in parallel, deterministically (per-chunk random streams), and cached in a file
// keyed by every parameter that changes it; a corrupt or mismatched cache is rebuilt.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "fvp/robot/arm_model.h"
#include "fvp/robot/reachability.h"

namespace fvp::robot {

/// Where a workspace tree is cached between runs when the arm config names no directory (the
/// simulator's trials, the ROS node): $FVP_CACHE_DIR, else $XDG_CACHE_HOME/fvp, else
/// ~/.cache/fvp, else a directory under the system temp dir.
std::string defaultCacheDir();

class WorkspaceTree : public Reachability {
 public:
  /// Samples config.workspace_samples configurations of `arm` (OpenMP threads).
  static WorkspaceTree build(const ArmModel& arm);
  /// The cached tree from workspace_cache_dir when it is there and valid; otherwise builds
  /// it and (with a cache dir) writes the cache atomically. Problems with the cache are
  /// warnings on `log`, never errors.
  static WorkspaceTree loadOrBuild(const ArmModel& arm, std::ostream& log);
  /// Reads a cache file; nullopt (and why) when it is missing, corrupt or for other keys.
  static std::optional<WorkspaceTree> load(const std::filesystem::path& path,
                                           const std::string& expected_key, std::string* why);
  /// Writes the cache file atomically (temporary file + rename).
  void save(const std::filesystem::path& path) const;

  /// Every parameter that changes the tree, as text (the cache file's key).
  static std::string cacheKey(const ArmModel& arm);
  /// workspace_cache_dir / workspace_<hash of the key>.bin; empty without a cache dir.
  static std::filesystem::path cachePath(const ArmModel& arm);

  bool reachable(const Eigen::Isometry3d& T_world_camera) const override;
  /// Position only: any viewing direction.
  bool reachablePosition(const Eigen::Vector3d& p_world_m) const;
  /// Samples that fell into this position cell and direction bin.
  int count(const Eigen::Vector3d& p_world_m, const Eigen::Vector3d& view_dir_world) const;

  double resolution_m() const { return resolution_m_; }
  int directionBins() const { return 6 * bins_per_edge_ * bins_per_edge_; }
  Eigen::Vector3i cells() const { return dims_; }
  std::uint64_t nonEmptyBins() const;
  bool fromCache() const { return from_cache_; }
  const std::string& key() const { return key_; }

 private:
  WorkspaceTree() = default;
  int cellIndex(const Eigen::Vector3d& p_world) const;  ///< -1 outside the box
  int directionBin(const Eigen::Vector3d& d_slider) const;
  void finish();  ///< derived per-cell flags after counts_ is filled

  std::string key_;
  Eigen::Vector3d slider_origin_m_ = Eigen::Vector3d::Zero();  ///< world frame
  double slider_yaw_rad_ = 0.0;
  Eigen::Matrix3d R_slider_world_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d origin_m_ = Eigen::Vector3d::Zero();  ///< grid's min corner, slider frame
  double resolution_m_ = 0.0;
  Eigen::Vector3i dims_ = Eigen::Vector3i::Zero();
  int bins_per_edge_ = 1;
  int min_count_ = 1;
  std::vector<std::uint16_t> counts_;   ///< [cell][direction bin], saturating
  std::vector<std::uint8_t> cell_any_;  ///< per cell: any bin reaches min_count
  bool from_cache_ = false;
};

}  // namespace fvp::robot
