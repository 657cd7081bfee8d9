// The one place a next-best-view run is assembled (OMPL's SimpleSetup is the model): given a
// planner, a map engine, a compute backend, a stop specification and the clusters to visit,
// it builds each cluster's mapping session, planner and stop and runs one cluster or a tour
// over several (docs/nbv-loop.md, "One setup"). A robot, the simulator's trials, the CLI and
// Python all run through it; the caller supplies the camera, the arm and the clock, and does
// any scoring against ground truth with what it reports.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fvp/accel/backend_choice.h"
#include "fvp/host/nbv/arm.h"
#include "fvp/host/nbv/camera.h"
#include "fvp/host/nbv/cluster_completion.h"
#include "fvp/host/nbv/loop_clock.h"
#include "fvp/host/nbv/nbv_loop.h"
#include "fvp/host/nbv/run_fields.h"
#include "fvp/host/nbv/stop_rule.h"
#include "fvp/host/nbv/visit_memory.h"
#include "fvp/host/perception/perception_pipeline.h"
#include "fvp/host/planner/view_planner.h"
#include "fvp/host/session/mapping_session.h"
#include "fvp/host/sizing/fruitlet_sizer.h"

namespace fvp::accel {
class Backend;
}

namespace fvp::host::nbv {

struct StopSpec {
  StopRule rule = StopRule::kBudget;
  /// Each cluster's cap, counted from its arrival on the run's clock (the paper: 180 s).
  double budget_s = 180.0;
  std::optional<int> max_views;  ///< each cluster stops after this many views (tests)
  /// kAuto's parameters (and those of record_size_history's sizings).
  ClusterCompletionConfig completion;
  /// Size the cluster after every view and keep the sizings (ClusterRun::size_history) also
  /// under kBudget, where they are an observation, not part of the loop: not charged to the
  /// clock. Always on with kAuto.
  bool record_size_history = false;
  /// The caller's request to end the run (an action's cancel, a shutdown), asked between the
  /// loop's steps: the cluster's loop stops ("cancelled") and a tour visits no further cluster.
  /// Empty: never.
  std::function<bool()> cancel;
  /// Throws std::invalid_argument naming the bad field.
  void validate() const;
};

/// A cluster to visit: the Cluster Region (from its tag, or given) and where to first look.
struct ClusterTarget {
  /// The cluster's AprilTag id (-1: any tag); none: the perception config's tag.
  std::optional<int> tag_id;
  /// An explicit Cluster Region centre (world frame): no tag needed.
  std::optional<Eigen::Vector3d> region_center_m;
  /// The first view of the cluster; a tour moves there (or to an approach view near it).
  Eigen::Isometry3d T_world_start_camera = Eigen::Isometry3d::Identity();
  /// About where the cluster is: approach views turn about the vertical through it.
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  /// What an earlier visit learned of it (docs/season.md, "Visits remembered"): its views are
  /// taken first, and with the automatic stop its fruitlets are looked for.
  std::optional<ClusterMemory> memory;
};

struct NbvSetupOptions {
  std::string planner = "fvp";           ///< a PlannerRegistry name
  std::filesystem::path planner_config;  ///< empty: the planner's defaults
  std::string engine;                    ///< a MapEngineRegistry name; empty: the planner's
  accel::BackendChoice backend = accel::BackendChoice::kAuto;
  /// Cluster k of a tour (its index in the targets) seeds its planner with planner_seed + k.
  std::uint64_t planner_seed = 1;
  /// Align each view to the earlier ones before fusing it (MappingSession::
  /// enableViewRegistration).
  bool register_views = false;
  /// Stereo's full-resolution pass over only the disparities of the Cluster Region and
  /// nearer (PerceptionConfig::disparity_window, which this sets for every cluster).
  bool disparity_window = false;
  /// Stereo's full-resolution pass by the guided kernels on the setup's backend
  /// (StereoMatcherConfig::guided_fine, which this sets for every cluster).
  bool guided_stereo = run_fields::kDefaultGuidedStereo;
  /// The farthest a remembered fruitlet's centre may stand from where an earlier visit saw it
  /// and still be that fruitlet (season::AssociationConfig::max_center_shift_m's reason:
  /// stems droop a few millimetres as fruitlets grow, plus each visit's registration error).
  double remembered_max_shift_m = 0.008;
  /// Perception for every cluster; the target's tag id and region replace the tag's and
  /// region's, disparity_window and guided_stereo above its own.
  PerceptionConfig perception;
  sizing::SizingConfig sizing;
  StopSpec stop;
  NbvLoopOptions loop;
  /// Checks every setting without creating anything; throws std::invalid_argument naming the
  /// bad one ("setting 'planner': expected one of fvp,rvp, got 'x'").
  void validate() const;
};

class RememberedViews;

/// One cluster's mapping session and planner: what the loop fills and the sizing reads.
struct ClusterWork {
  std::unique_ptr<MappingSession> session;
  std::unique_ptr<planner::ViewPlanner> planner;
  map::MapConfig map_config;  ///< the maps' config, as the session got it
  /// With the target's memory: the planner (a RememberedViews) and the fruitlets to expect.
  RememberedViews* remembered = nullptr;
  std::vector<RememberedFruitlet> expected;
};

/// What a cluster's memory did (ClusterTarget::memory).
struct MemoryUse {
  std::size_t views = 0, views_taken = 0;  ///< remembered views, and those the arm took
  /// Remembered fruitlets, those the loop's last sizing found within the gate, and those looked
  /// for in vain (gone); the rest were neither (the stop ended first, or not the automatic one).
  std::size_t fruitlets = 0, found = 0, gone = 0;
  /// Memory accounted for the cluster's fruitlets at the last sizing
  /// (SizingGuidance::fruitletsKnown), whichever stop ended the loop and whether or not
  /// known_fruitlets was on.
  bool known = false;
};

/// What running the loop on one cluster gave.
struct ClusterRun {
  NbvResult run;
  double start_s = 0.0;                      ///< the run's clock when the cluster's loop began
  sizing::SizingResult sizing;               ///< the cluster sized after its loop
  double sizing_wall_s = 0.0;                ///< that sizing's wall time
  double sizing_during_loop_s = 0.0;         ///< the stop's sizings after each view, summed
  std::vector<SizingSnapshot> size_history;  ///< with kAuto or record_size_history
  /// With kAuto, what the sizing guidance did: views aimed at fruitlets the stop waited for
  /// and targets it gave up on.
  std::size_t sizing_views = 0, sizing_targets_dropped = 0;
  /// Views of the tour's earlier approach views that showed no tag (their poses lead
  /// run.camera_poses and are counted in run.views).
  int approaches_without_tag = 0;
  std::optional<MemoryUse> memory;  ///< with the target's memory
};

/// How a tour's visit of a cluster ended.
enum class VisitStatus {
  kSized,        ///< its loop ran with a Cluster Region
  kNoTag,        ///< no view of it (from any approach view) showed its tag
  kUnreachable,  ///< no approach view was reachable (workspace tree)
  kMoveFailed,   ///< approach views were tried and every move failed
};
/// "sized", "no_tag", "unreachable", "move_failed" (result.json's clusters[].status).
const char* toString(VisitStatus status);

/// One cluster of a tour.
struct ClusterVisit {
  std::size_t index = 0;  ///< into the targets
  VisitStatus status = VisitStatus::kUnreachable;
  double arrival_s = 0.0;  ///< the run's clock when the tour turned to it (before the move)
  /// The approach view the loop started from: its distance from the cluster's centre and its
  /// turn about the vertical through it (none: the arm was already at the start view).
  std::optional<double> approach_distance_m, approach_yaw_deg;
  /// The clock when the cluster's first loop began (after the approach move).
  double loop_start_s = 0.0;
  /// The last approach move's status (MoveStatus's name, "unreachable" when none was tried).
  std::string move_status;
  std::optional<ClusterRun> run;  ///< for kSized and kNoTag
};

/// Hears of a tour's clusters as well as of every view and plan (LoopObserver).
class TourObserver : public LoopObserver {
 public:
  /// The loop on cluster `index` is about to start (the arm is at its first view).
  virtual void onClusterStart(std::size_t index, const ClusterTarget& target) {
    (void)index;
    (void)target;
  }
  /// The cluster is done, sized, and its work (session, planner) is still whole: the
  /// moment to read or save its maps before the coarse map moves on to the next cluster.
  virtual void onClusterDone(const ClusterVisit& visit, const ClusterWork& work) {
    (void)visit;
    (void)work;
  }
  /// A cluster the tour could not start (kUnreachable, kMoveFailed).
  virtual void onClusterSkipped(const ClusterVisit& visit) { (void)visit; }
};

struct TourResult {
  std::vector<ClusterVisit> visits;  ///< in visit order
  double transit_s = 0.0;            ///< the clock spent moving between clusters
  /// Of transit_s, the arm's motion (MoveResult::motion_s); the rest is the moves' planning.
  double transit_motion_s = 0.0;
  std::map<std::string, std::size_t> transit_motion;  ///< MoveStatus name -> count
  /// The map the last sized cluster handed on (its coarse map covers the whole tour).
  std::unique_ptr<map::MapEngine> map;
};

/// The robot the setup drives: all three must outlive a run.
struct NbvRig {
  Camera& camera;
  Arm& arm;
  LoopClock& clock;
};

class ApproachSequence;

class NbvSetup {
 public:
  /// Checks the options, creates the backend and reads the planner's config (a missing
  /// backend or a bad config throws here, before anything moves).
  explicit NbvSetup(NbvSetupOptions options);
  ~NbvSetup();
  NbvSetup(const NbvSetup&) = delete;
  NbvSetup& operator=(const NbvSetup&) = delete;

  /// A cluster's session and planner, ready for its loop; `index` seeds its planner
  /// (planner_seed + index).
  std::unique_ptr<ClusterWork> makeWork(const ClusterTarget& target, std::size_t index = 0);

  /// The loop on one cluster from where the arm is, until the stop, then its sizing.
  ClusterRun runCluster(const NbvRig& rig, ClusterWork& work, LoopObserver* observer = nullptr);

  /// The clusters one after another on one clock and one coarse map, in the order that
  /// reaches their start views in the least time (Arm::travelTime_s, tour_order.h; ordered
  /// again from where each cluster ended, and charged as planning); each from its start view or,
  /// where the arm cannot stand there, an approach view backed off along its axis and then turned
  /// about the cluster; a cluster whose views show no tag is retried from its next approach view. A
  /// cluster the arm cannot reach is skipped and counted.
  TourResult runTour(const NbvRig& rig, const std::vector<ClusterTarget>& targets,
                     TourObserver* observer = nullptr);

  const NbvSetupOptions& options() const { return options_; }
  /// The engine runs use (the planner's default when options().engine is empty).
  const std::string& engine() const { return engine_; }
  /// The compute backend (null for an engine that needs none and no backend asked for).
  accel::Backend* backend() const { return backend_.get(); }

 private:
  ClusterRun runFromApproaches(const NbvRig& rig, ClusterWork& work, ApproachSequence& approach,
                               LoopObserver* observer, ClusterVisit& visit, TourResult& tour);

  NbvSetupOptions options_;
  std::string engine_;
  std::unique_ptr<accel::Backend> backend_;
  /// The planner of cluster index 0, built by the constructor to check the config.
  std::unique_ptr<planner::ViewPlanner> first_planner_;
};

}  // namespace fvp::host::nbv
