// One simulated trial (docs/design.md section 9, `fvp run`): a world from a seed, the start view,
// the AprilTag -> Cluster Region, then planning iterations until the simulated budget is
// spent (capture -> perceive -> maps + TSDF -> sample -> score -> move), then sizing and
// scoring against ground truth. The experiment runner (`fvp experiment`) calls it once per
// planner and seed.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "fvp/accel/backend_choice.h"
#include "fvp/host/nbv/run_fields.h"
#include "fvp/host/nbv/stop_rule.h"
#include "fvp/host/planner/view_overhead.h"
#include "fvp/robot/sim/sim_clock.h"

namespace fvp::host {
struct StereoFrame;
}

namespace fvp::host::nbv {
class Arm;
class Camera;
}  // namespace fvp::host::nbv

namespace fvp::trials {

/// Where a running trial is, for progress displays.
struct TrialProgress {
  int views = 0;           ///< views captured so far
  double sim_time_s = 0;   ///< simulated clock
  double budget_s = 0;     ///< simulated budget
  double wall_time_s = 0;  ///< wall time since the trial started
};

struct TrialOptions {
  std::string planner = "fvp";  ///< "fvp" or "rvp"
  std::uint64_t seed = 1;
  std::filesystem::path world_config;  ///< empty: robot/sim/config/world_default.yaml
  /// The season's day to visit (docs/simulation.md "A season"); none: the world config's
  /// season_day.
  std::optional<double> season_day;
  std::filesystem::path planner_config;  ///< empty: the planner's default config
  std::filesystem::path arm_config;  ///< empty: the built-in arm (robot/config/arm_default.yaml)
  double budget_s = 180.0;           ///< simulated seconds (paper: 180)
  accel::BackendChoice backend = accel::BackendChoice::kAuto;
  std::string engine;            ///< grid | octomap; empty: the planner's default
  std::optional<int> max_views;  ///< stop after this many views (tests)
  /// wall: compute charged as measured; fixed: as constants (runs repeat exactly).
  robot::sim::SimClock::Mode clock = robot::sim::SimClock::Mode::kWall;
  /// budget: the paper's protocol (budget_s, max_views); auto: also stop once the cluster's
  /// sizes have settled (host/nbv/cluster_completion.h), budget_s being the cap.
  host::nbv::StopRule stop = host::nbv::StopRule::kBudget;
  /// Size the cluster after every view and keep each sizing, scored, in result.json's
  /// size_history (always with stop auto). Under stop budget it is an observation for the
  /// accuracy-against-time figure, not part of the loop: not charged to the clock.
  bool record_size_history = false;
  /// Align each view to the earlier ones before fusing it (MappingSession::
  /// enableViewRegistration; docs/sizing.md "Registering views"): the counter-measure to
  /// pose errors. Off: the paper's fusion at the told poses.
  /// none: as the world config says (run_register_views; the field preset: on).
  std::optional<bool> register_views;
  /// With stop auto: look again at unconfirmed detections (dropped by the hemisphere rule
  /// alone) before a cluster is done (host::nbv::ClusterCompletionConfig::confirm_detections).
  bool confirm_detections = true;
  /// With stop auto: look again at partly seen detections (dropped by the support rule, apart
  /// from every kept fruitlet) before a cluster is done
  /// (host::nbv::ClusterCompletionConfig::seek_partly_seen).
  bool seek_partly_seen = true;
  /// With stop auto: a fruitlet the planner looked for twice in vain no longer holds the stop
  /// (host::nbv::ClusterCompletionConfig::release_left_out).
  bool release_left_out = true;
  /// With stop auto, on a season's later visit: memory accounting for a cluster's fruitlets
  /// shortens its stop (host::nbv::ClusterCompletionConfig::known_fruitlets).
  bool known_fruitlets = true;
  /// Stereo's full-resolution pass over only the disparities of the Cluster Region and nearer
  /// (host::PerceptionConfig::disparity_window).
  bool disparity_window = false;
  /// Stereo's full-resolution pass by the guided kernels on the trial's backend
  /// (host::StereoMatcherConfig::guided_fine).
  bool guided_stereo = host::nbv::run_fields::kDefaultGuidedStereo;
  /// Seconds a view costs besides the arm's move: views that pass the goal check are tried
  /// by information per second (host::nbv::NbvLoopOptions::view_overhead_s); 0: the
  /// planner's order.
  double view_overhead_s = host::planner::kDefaultViewOverheadS;
  /// An earlier visit of the same tree (its result.json, or the directory holding it): each
  /// cluster starts from what that visit learned, aligned through its tag (docs/season.md,
  /// "Visits remembered"). Empty: none. Recorded in result.json's "remembered_visit".
  std::filesystem::path remembered_visit;
  /// Where result.json, the maps, the TSDF surface, the clusters and report.md go; empty:
  /// nothing is written (the result is only returned).
  std::filesystem::path out_dir;
  std::function<void(const TrialProgress&)> on_progress;  ///< called after every view
  /// Called with every frame the trial captured, as the camera gave it (its told pose, and a
  /// mask or disparity where the camera gives them), and the simulated time it was mapped at:
  /// to record a trial (fvp run --bag).
  std::function<void(const host::StereoFrame&, double sim_time_s)> on_frame;
  /// Called with each warning as it happens (a rebuilt workspace cache, a figure not
  /// drawn, a view without fruitlet pixels); every warning is also in result["warnings"].
  std::function<void(const std::string&)> on_warning;
};

/// Runs one trial and returns its result.json object (the contract of docs/design.md section 9),
/// also written atomically to out_dir/result.json when out_dir is set. out_dir is checked
/// before the trial starts and the files an earlier trial left there are removed; result.json
/// is written before the extras (maps, clouds, figures), and a figure that cannot be drawn is
/// a warning, not an error. Throws
/// std::invalid_argument / std::runtime_error for bad options or files (misconfiguration);
/// expected events (failed motions, IK failures, dropped disparities, empty clusters) are
/// counted in the result, never thrown.
nlohmann::json runTrial(const TrialOptions& options);

/// One trial built and not yet run: the world, the simulated camera, arm and clock, the
/// mapping session and the planner (construction checks the options, the configs and the
/// backend, and clears out_dir). run() drives the next-best-view loop through the
/// simulated camera and arm, or through the caller's own, which may wrap these (the Python
/// bindings' proof that the loop takes a user's camera and arm); the loop's clock is the
/// simulated one either way. A trial runs once.
class Trial {
 public:
  explicit Trial(TrialOptions options);
  ~Trial();
  Trial(const Trial&) = delete;
  Trial& operator=(const Trial&) = delete;

  /// The renderer at the given pose, each capture charged to the simulated clock.
  host::nbv::Camera& simulatedCamera();
  /// The UR5 on its slider: workspace-tree reachability, IK + OMPL, charged moves.
  host::nbv::Arm& simulatedArm();

  /// The result.json object, as runTrial's. Throws std::logic_error when called twice.
  nlohmann::json run();
  nlohmann::json run(host::nbv::Camera& camera, host::nbv::Arm& arm);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Whether the trial registers views: the option when set, else the world config's
/// run_register_views (reads the world config; throws for a bad one).
bool registerViewsOf(const TrialOptions& options);

/// A short, readable summary of a result.json object: sizes against ground truth, views,
/// simulated and wall time (what `fvp run` and scripts/demo print).
std::string trialSummary(const nlohmann::json& result);

}  // namespace fvp::trials
