// The parts of one simulated trial that change with the planner and the pipeline stages:
// the per-view mapping session (perception -> maps -> TSDF), the viewpoint planner, the
// views kept for sizing, the sizing and scoring against ground truth, and a cluster's files
// (report.md and the figures: trial_report.h). trial.cpp holds the loop and the clock; this
// holds what the loop drives.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fvp/host/eval/ground_truth.h"
#include "fvp/host/map/map_config.h"
#include "fvp/host/nbv/nbv_setup.h"
#include "fvp/host/perception/stereo_frame.h"
#include "fvp/host/planner/view_planner.h"
#include "fvp/host/session/mapping_session.h"
#include "fvp/robot/sim/world.h"
#include "fvp/robot/workspace_tree.h"
#include "fvp/trials/trial.h"
#include "trial_report.h"  // ExtraWriter; and for trial.cpp, the report's writers

namespace fvp::accel {
class Backend;
}

namespace fvp::trials {

/// The arm's workspace tree from its cache (built and cached when missing or stale); each
/// warning the cache gave (a stale or unreadable file, a cache it could not write) goes to
/// warn, without its "warning: " prefix.
robot::WorkspaceTree loadWorkspaceTree(const robot::ArmModel& arm,
                                       const std::function<void(const std::string&)>& warn);

/// The ground truth of the world's fruitlets with these indices (a cluster's).
std::vector<host::eval::GroundTruthFruitlet> groundTruthOf(const robot::sim::World& world,
                                                           const std::vector<int>& indices);

/// A trial's view of one cluster's work (the library's session and planner, NbvSetup):
/// its configuration for result.json, its sizing scored against the world, and its files.
class TrialParts {
 public:
  /// work must outlive this.
  TrialParts(const TrialOptions& options, const std::string& engine,
             const host::nbv::ClusterWork& work);

  const host::MappingSession& session() const { return *work_.session; }
  const host::planner::ViewPlanner& planner() const { return *work_.planner; }
  /// The trial-level configuration (engine, map, perception, sizing) as JSON.
  nlohmann::json configJson(const host::sizing::SizingConfig& sizing_config) const;
  /// The cluster's sizing scored against the ground truth of the fruitlets with these
  /// indices in the world (the cluster's): {"fruitlets", "detections", "metrics", ...} of
  /// result.json. Kept for writeClusterFiles. With the cluster's true tag pose and a tag
  /// seen, also "metrics_tag_frame": the same scoring with each detection placed in the world
  /// through the true tag from its centre in the seen tag's frame (what a grower with tagged
  /// clusters can check: the shared pose error cancels).
  nlohmann::json score(host::sizing::SizingResult sizing, host::sizing::SizingEstimator estimator,
                       const robot::sim::World& world, const std::vector<int>& fruitlet_indices,
                       const std::optional<Eigen::Isometry3d>& T_world_tag_true = std::nullopt);
  /// The cluster's files from the last score, each atomically, into dir: fine.ot (while
  /// the session holds its map), surface.ply, mesh.ply and clusters.ply.
  void writeClusterFiles(const std::filesystem::path& dir, const ExtraWriter& extra) const;
  /// Those files' names.
  static const std::vector<std::string>& clusterFiles();
  /// result.json first, then the maps, surface, clusters, the camera-path figure and
  /// report.md, each atomically, into out_dir. A figure that cannot be drawn is passed to
  /// warn and added to result["warnings"] (result.json is written again then).
  void writeOutputs(nlohmann::json& result, const robot::sim::World& world,
                    const std::vector<Eigen::Vector3d>& camera_path,
                    const std::filesystem::path& out_dir,
                    const std::function<void(const std::string&)>& warn,
                    const ExtraWriter& extra) const;
  /// The files writeOutputs writes (relative to out_dir), besides views/NNN.png.
  static const std::vector<std::string>& outputFiles();

 private:
  const TrialOptions& options_;
  std::string engine_;
  const host::nbv::ClusterWork& work_;
  host::sizing::SizingResult sizing_;  ///< of the last score
};

}  // namespace fvp::trials
