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
#include <string>
#include <vector>

#include "fvp/host/eval/ground_truth.h"
#include "fvp/host/map/map_config.h"
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

/// The map engine a planner runs on unless --engine says otherwise (its registry entry's:
/// FVP grid, RVP octomap, as the original did).
std::string defaultEngine(const std::string& planner);
/// Where the workspace tree is cached between trials: $FVP_CACHE_DIR, else
/// $XDG_CACHE_HOME/fvp, else ~/.cache/fvp, else a directory under the system temp dir.
std::string defaultCacheDir();
/// The arm's workspace tree from its cache (built and cached when missing or stale); each
/// warning the cache gave (a stale or unreadable file, a cache it could not write) goes to
/// warn, without its "warning: " prefix.
robot::WorkspaceTree loadWorkspaceTree(const robot::ArmModel& arm,
                                       const std::function<void(const std::string&)>& warn);

/// The ground truth of the world's fruitlets with these indices (a cluster's).
std::vector<host::eval::GroundTruthFruitlet> groundTruthOf(const robot::sim::World& world,
                                                           const std::vector<int>& indices);

/// What one view did, with the wall times the clock charges.
struct ViewOutcome {
  host::ViewResult result;
  double mapping_s = 0.0;  ///< map integration (charged as mapping)
  double tsdf_s = 0.0;     ///< TSDF integration (charged as TSDF)
};

class TrialParts {
 public:
  /// perception: the tag (and so the cluster) this part's session maps; planner_seed seeds
  /// its planner (the trial's seed for one cluster).
  TrialParts(const TrialOptions& options, const std::string& engine, accel::Backend* backend,
             const host::PerceptionConfig& perception, std::uint64_t planner_seed);
  ~TrialParts();

  ViewOutcome addView(const host::StereoFrame& frame);
  /// Null until a view detected the tag.
  host::map::MapEngine* map();
  host::planner::ViewPlanner& planner();
  host::MappingSession& session();
  const host::sizing::SizingConfig& sizingConfig() const;
  /// The trial-level configuration (engine, map, perception, sizing) as JSON.
  nlohmann::json configJson() const;
  /// Sizes the fruitlets from the views so far and scores them against the ground truth of
  /// the fruitlets with these indices in the world (the cluster's): {"fruitlets",
  /// "detections", "metrics", ...} of result.json.
  nlohmann::json sizeAndScore(const robot::sim::World& world,
                              const std::vector<int>& fruitlet_indices);
  /// The cluster's files from the last sizeAndScore, each atomically, into dir: fine.ot (while
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
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fvp::trials
