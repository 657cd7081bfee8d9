#include "fvp/trials/trial.h"

#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "fvp/accel/backend.h"
#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/interrupt.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/eval/fruitlet_matching.h"
#include "fvp/host/eval/sizing_score.h"
#include "fvp/host/map/map_engine_registry.h"
#include "fvp/host/nbv/cluster_completion.h"
#include "fvp/host/nbv/loop_observers.h"
#include "fvp/host/nbv/nbv_loop.h"
#include "fvp/host/nbv/sizing_guidance.h"
#include "fvp/host/planner/planner_registry.h"
#include "fvp/host/planner/view_planner.h"
#include "fvp/host/report/viewer_scene.h"
#include "fvp/host/session/mapping_session.h"
#include "fvp/host/session/session_report.h"
#include "fvp/robot/arm_model.h"
#include "fvp/robot/sim/simulated_arm.h"
#include "fvp/robot/sim/simulated_camera.h"
#include "fvp/robot/sim/simulated_loop_clock.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/world.h"
#include "fvp/robot/workspace_tree.h"
#include "trial_parts.h"
#include "trial_viewer.h"

namespace fvp::trials {
// The simulator's parts and the arm, by their short names.
using namespace fvp::robot;
using namespace fvp::robot::sim;
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

using host::report::vec3Json;

/// How far the camera really was from where the robot was told it was: the translation
/// (mm) and rotation (deg) of T_told^-1 T_true (zero without pose errors).
nlohmann::json poseErrorJson(const Eigen::Isometry3d& T_told, const Eigen::Isometry3d& T_true) {
  const Eigen::Isometry3d d = T_told.inverse() * T_true;
  return {{"translation_mm", 1000.0 * d.translation().norm()},
          {"rotation_deg", Eigen::AngleAxisd(d.rotation()).angle() * 180.0 / std::numbers::pi}};
}

/// With view registration: where the registered maps sit off the world as the views tell,
/// whether the reported positions were moved by it, and, where the simulator has pose
/// errors, the anchor frame's true error at the cluster's centre before and after.
nlohmann::json anchorOffsetJson(const host::MappingSession& session,
                                const std::optional<Eigen::Vector3d>& true_anchor_error_m) {
  const host::AnchorOffset offset = session.anchorOffset();
  nlohmann::json j = {{"shift_mm", vec3Json(1000.0 * offset.shift_m)},
                      {"hand_eye_mm", vec3Json(1000.0 * offset.hand_eye_m)},
                      {"views", offset.views},
                      {"valid", offset.valid},
                      {"applied", session.correctsAnchorOffset() && offset.valid}};
  if (true_anchor_error_m) {
    j["anchor_error_mm"] = 1000.0 * true_anchor_error_m->norm();
    j["corrected_error_mm"] = 1000.0 * (*true_anchor_error_m - offset.shift_m).norm();
  }
  return j;
}

/// R_world_camera as [w, x, y, z]; the camera looks along its z axis (OpenCV frame).
nlohmann::json quaternionWxyz(const Eigen::Isometry3d& T) {
  return host::report::poseJson(T).at("quaternion_wxyz");
}

void validate(const TrialOptions& o) {
  if (!host::planner::PlannerRegistry::instance().contains(o.planner))
    throw std::invalid_argument("trial option 'planner': expected one of " +
                                host::planner::PlannerRegistry::instance().knownNames() +
                                ", got '" + o.planner + "'");
  if (!(o.budget_s > 0.0) || !std::isfinite(o.budget_s))
    throw std::invalid_argument("trial option 'budget_s': expected a positive number of seconds");
  if (o.clock != "wall" && o.clock != "fixed")
    throw std::invalid_argument("trial option 'clock': expected wall or fixed, got '" + o.clock +
                                "'");
  if (!o.engine.empty() && !host::map::MapEngineRegistry::instance().contains(o.engine))
    throw std::invalid_argument("trial option 'engine': expected one of " +
                                host::map::MapEngineRegistry::instance().knownNames() + ", got '" +
                                o.engine + "'");
  if (o.stop != "budget" && o.stop != "auto")
    throw std::invalid_argument("trial option 'stop': expected budget or auto, got '" + o.stop +
                                "'");
  if (o.max_views && *o.max_views < 1)
    throw std::invalid_argument("trial option 'max_views': expected at least 1");
}

/// The trial's per-view and per-iteration logs, view images and progress lines, from the
/// loop's observer hooks.
class TrialLog : public host::nbv::LoopObserver {
 public:
  TrialLog(const SimulatedCamera& camera, const TrialOptions& options, Clock::time_point wall_start)
      : camera_(camera), options_(options), wall_start_(wall_start) {}

  /// The views that follow are of this cluster of a tree (their log entries say which).
  void startCluster(int cluster, const Eigen::Vector3d& center_m) {
    cluster_ = cluster;
    first_view_ = static_cast<int>(views_.size());
    cluster_center_m_ = center_m;
    anchor_shifts_m_.clear();
  }

  void onView(const host::nbv::ViewEvent& e) override {
    const host::ViewResult& v = *e.result;
    const int index = first_view_ + e.index;  // over the whole run
    views_.push_back({{"index", index},
                      {"position_m", vec3Json(e.T_world_camera.translation())},
                      {"quaternion_wxyz", quaternionWxyz(e.T_world_camera)},
                      {"viewing_direction", vec3Json(e.T_world_camera.linear().col(2))},
                      {"tag_detected", v.tag_detected},
                      {"roi_points", v.roi_points},
                      {"other_points", v.other_points},
                      {"coarse_voxels_updated", v.scan.coarse_voxels_updated},
                      {"fine_voxels_updated", v.scan.fine_voxels_updated},
                      {"render_s", camera_.lastRenderSeconds()},
                      {"perceive_s", v.perceive_s},
                      {"mapping_s", v.scan.seconds},
                      {"tsdf_s", v.tsdf_s},
                      {"sim_time_s", e.now_s}});
    if (cluster_ >= 0) views_.back()["cluster"] = cluster_;
    if (camera_.hasPoseErrors()) {
      views_.back()["pose_error"] = poseErrorJson(e.T_world_camera, camera_.lastTruePose());
      // Where the view's told pose puts a point at the cluster's centre, moved back to the truth.
      if (cluster_center_m_) {
        const Eigen::Vector3d shift =
            camera_.lastTruePose() * e.T_world_camera.inverse() * *cluster_center_m_ -
            *cluster_center_m_;
        views_.back()["true_shift_mm"] = vec3Json(1000.0 * shift);
        if (!v.registration || v.registration->status == host::RegistrationStatus::kNoModel)
          anchor_shifts_m_.push_back(shift);
      }
    }
    if (v.registration) {
      const host::RegistrationResult& r = *v.registration;
      views_.back()["registration"] = {
          {"status", host::toString(r.status)},
          {"correction_mm", vec3Json(r.status == host::RegistrationStatus::kApplied
                                         ? Eigen::Vector3d(1000.0 * r.centroid_shift_m)
                                         : Eigen::Vector3d::Zero())},
          {"translation_mm", 1000.0 * r.translation_m},
          {"rotation_deg", r.rotation_deg},
          {"rms_before_mm", 1000.0 * r.rms_before_m},
          {"rms_after_mm", 1000.0 * r.rms_after_m},
          {"pairs", r.pairs}};
    }
    if (!options_.out_dir.empty()) {
      view_pngs_.emplace_back(index, encodeViewImage(index, *e.frame));
      images_.add(index, e.frame->left_bgr);
      if (!intrinsics_) intrinsics_ = e.frame->intrinsics;
    }
    if (options_.on_progress)
      options_.on_progress({index + 1, e.now_s, options_.budget_s, secondsSince(wall_start_)});
    host::throwIfInterrupted();  // a signal ends the loop after the view
  }

  void onPlan(const host::nbv::PlanEvent& e) override {
    host::throwIfInterrupted();
    const host::planner::PlanStep& step = *e.step;
    nlohmann::json timings = nlohmann::json::object();
    for (const auto& [stage, s] : step.timings_s) timings[stage] = s;
    plans_.push_back(
        {{"candidates", step.candidates.size()},
         {"moved", step.moved()},
         {"move_attempts", step.move_attempts},
         {"failed_moves", step.failed_moves},
         {"sampling_rounds", step.sampling_rounds},
         {"chosen_utility",
          step.chosen ? nlohmann::json(step.candidates[*step.chosen].utility) : nlohmann::json()},
         {"chosen_kind",
          step.chosen ? nlohmann::json(host::planner::toString(step.candidates[*step.chosen].kind))
                      : nlohmann::json()},
         {"chosen_position_m",
          step.chosen ? vec3Json(step.candidates[*step.chosen].position_m()) : nlohmann::json()},
         {"chosen_quaternion_wxyz",
          step.chosen ? quaternionWxyz(step.candidates[*step.chosen].T_world_camera)
                      : nlohmann::json()},
         {"planning_s", e.planning_s},
         {"timings_s", timings}});
    if (cluster_ >= 0) plans_.back()["cluster"] = cluster_;
  }

  const nlohmann::json& views() const { return views_; }
  const nlohmann::json& plans() const { return plans_; }
  /// With pose errors and the cluster's centre known: the mean of the anchor views' true
  /// displacement there (what the registered map's shift should be).
  void setClusterCenter(const Eigen::Vector3d& c) { cluster_center_m_ = c; }
  std::optional<Eigen::Vector3d> trueAnchorShift() const {
    if (anchor_shifts_m_.empty()) return std::nullopt;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const auto& d : anchor_shifts_m_) sum += d;
    return sum / double(anchor_shifts_m_.size());
  }
  /// The views' images for the overlays (kept only with an output directory).
  const ViewImages& images() const { return images_; }
  /// views/NNN.png of each view so far (index, PNG bytes), written after result.json.
  const std::vector<std::pair<int, std::string>>& viewPngs() const { return view_pngs_; }
  const std::optional<host::StereoIntrinsics>& intrinsics() const { return intrinsics_; }
  /// The run's number of this cluster's first view.
  int firstView() const { return first_view_; }

 private:
  const SimulatedCamera& camera_;
  const TrialOptions& options_;
  ViewImages images_;
  std::vector<std::pair<int, std::string>> view_pngs_;
  std::optional<host::StereoIntrinsics> intrinsics_;
  Clock::time_point wall_start_;
  int cluster_ = -1, first_view_ = 0;  ///< -1: a one-cluster world
  std::optional<Eigen::Vector3d> cluster_center_m_;
  std::vector<Eigen::Vector3d> anchor_shifts_m_;
  nlohmann::json views_ = nlohmann::json::array(), plans_ = nlohmann::json::array();
};

/// Each view's entry in view_log gets "sized": the kept detections of a cluster's sizing (its
/// per_image views counted from first_view) that the view gave a size to.
void markSizedViews(nlohmann::json& view_log, const nlohmann::json& sizing, int first_view,
                    std::optional<int> cluster) {
  if (!sizing.contains("sized_fruitlets")) return;
  std::size_t k = 0;
  for (const auto& d : sizing["sized_fruitlets"]) {
    for (const auto& s : d.at("per_image")) {
      const std::size_t view = static_cast<std::size_t>(first_view + s.at("view").get<int>());
      if (view < view_log.size())
        view_log[view]["sized"].push_back(host::report::detectionLabel(true, k, cluster));
    }
    ++k;
  }
}

/// The log's view images, as the overlays ask for them.
std::function<cv::Mat(int)> imageSource(const TrialLog& log) {
  return [&log](int view) { return log.images().image(view); };
}

/// The loop clock as an observer sees it: the time, with nothing charged (sizing for a
/// figure is not part of the loop).
class UnchargedClock : public host::nbv::LoopClock {
 public:
  explicit UnchargedClock(const host::nbv::LoopClock& clock) : clock_(clock) {}
  double now_s() const override { return clock_.now_s(); }

 private:
  const host::nbv::LoopClock& clock_;
};

/// The cluster as the automatic stop sized it after each view, each sizing scored against
/// the world's ground truth: what a shorter budget would have reported.
/// Times are from the start of the cluster (t0_s on the run's clock).
nlohmann::json sizeHistoryJson(const std::vector<host::nbv::SizingSnapshot>& history,
                               const World& world, const std::vector<int>& fruitlet_indices,
                               double t0_s) {
  std::vector<Eigen::Vector3d> truth_m;
  std::vector<double> truth_mm;
  for (const auto& g : groundTruthOf(world, fruitlet_indices)) {
    truth_m.push_back(g.center_m);
    truth_mm.push_back(g.size_mm);
  }
  nlohmann::json out = nlohmann::json::array();
  for (const auto& snapshot : history) {
    std::vector<Eigen::Vector3d> centres;
    std::vector<double> sizes;
    nlohmann::json fruitlets = nlohmann::json::array();
    for (const auto& f : snapshot.fruitlets) {
      centres.push_back(f.center_m + snapshot.world_shift_m);
      sizes.push_back(f.size_mm);
      fruitlets.push_back({{"center_m", vec3Json(f.center_m + snapshot.world_shift_m)},
                           {"size_mm", f.size_mm},
                           {"well_seen_images", f.well_seen_images},
                           {"view_span_deg", f.view_span_deg},
                           {"size_stderr_mm", f.size_stderr_mm},
                           {"size_source", host::sizing::toString(f.size_source)}});
    }
    const auto m = host::eval::sizeMetrics(
        truth_mm, sizes, host::eval::matchFruitlets(centres, truth_m), centres.size());
    const auto opt = [](const std::optional<double>& v) {
      return v ? nlohmann::json(*v) : nlohmann::json();
    };
    out.push_back({{"view", snapshot.view},
                   {"sim_time_s", snapshot.now_s - t0_s},
                   {"sizing_wall_s", snapshot.sizing_s},
                   {"fruitlets", fruitlets},
                   {"match_percent", m.match_percent},
                   {"mae_mm", opt(m.mae_mm)},
                   {"precision_percent", opt(m.precision_percent)}});
  }
  return out;
}

// A cluster's start view and the same view from farther out: its camera body (3 cm) with
// the collision padding (1 cm) and a coarse voxel (1 cm) needs about 5 cm around it, and
// leaves may hang that close to the start view (the generator keeps them 5 cm off the
// camera centre), so each step backs off by that much; 0.45 m is the farthest, where the
// 3 cm tag still spans about 70 px. Where none of those can be reached (the foliage an
// earlier cluster's views mapped may stand where the arm must), the same views turned about
// the vertical through the cluster's centre by 20 and then 40 degrees either way: the tag,
// tilted at most 5 degrees, is then seen 45 degrees off its axis at most, well inside what
// AprilTag detects.
constexpr double kApproachStepM = 0.05;
constexpr int kApproachSteps = 3;
constexpr std::array<double, 5> kApproachYawDeg = {0.0, 20.0, -20.0, 40.0, -40.0};

struct ApproachPose {
  Eigen::Isometry3d T_world_camera;
  double yaw_deg = 0.0;  ///< turned about the vertical through the cluster's centre
};

std::vector<ApproachPose> approachPoses(const FruitletCluster& cluster) {
  std::vector<ApproachPose> poses;
  const Eigen::Vector3d back = -cluster.T_world_start_camera.linear().col(2);
  for (const double yaw_deg : kApproachYawDeg) {
    const Eigen::Isometry3d turn =
        Eigen::Translation3d(cluster.center_m) *
        Eigen::AngleAxisd(yaw_deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()) *
        Eigen::Translation3d(-cluster.center_m);
    for (int step = 0; step <= kApproachSteps; ++step) {
      Eigen::Isometry3d T = cluster.T_world_start_camera;
      T.translation() += step * kApproachStepM * back;
      poses.push_back({turn * T, yaw_deg});
    }
  }
  return poses;
}

/// The cluster not yet visited whose start view is nearest `here` (the first on a tie).
std::size_t nearestUnvisited(const std::vector<FruitletCluster>& clusters,
                             const std::vector<bool>& visited, const Eigen::Vector3d& here) {
  std::size_t k = clusters.size();
  for (std::size_t i = 0; i < clusters.size(); ++i)
    if (!visited[i] && (k == clusters.size() ||
                        (clusters[i].T_world_start_camera.translation() - here).norm() <
                            (clusters[k].T_world_start_camera.translation() - here).norm()))
      k = i;
  return k;
}

/// What a tree's tour has gathered so far, cluster by cluster: result.json's parts.
struct TourRecord {
  nlohmann::json cluster_entries = nlohmann::json::array();
  nlohmann::json order = nlohmann::json::array();
  nlohmann::json scored = nlohmann::json::object();  // "fruitlets..." arrays over the clusters
  nlohmann::json events = nlohmann::json::object(), wall = nlohmann::json::object();
  nlohmann::json transit_motion = nlohmann::json::object();
  std::map<std::string, int> cluster_status;
  std::vector<Eigen::Vector3d> camera_path;
  nlohmann::json cluster_write_failures = nlohmann::json::object();  // as extraWriter records
  std::uint64_t detections = 0;
  int views = 0;
  double transit_s = 0.0;
  nlohmann::json planner_config, trial_config;
  std::string scene_error;  // why the scene could not be built (no viewer then)
  nlohmann::json overlays = nlohmann::json::array();
};

/// A cluster's approach views (approachPoses), tried in order: each moveToNext moves the arm
/// to the next one it can reach, charging the transit to the tour, until a move succeeds.
class ApproachSequence {
 public:
  explicit ApproachSequence(const FruitletCluster& cluster)
      : cluster_(cluster), poses_(approachPoses(cluster)) {}

  /// False when no approach view is left; a success records the view in `entry`.
  bool moveToNext(host::nbv::Arm& arm, host::nbv::LoopClock& clock, nlohmann::json& entry,
                  TourRecord& tour) {
    for (; next_ < poses_.size(); ++next_) {
      const auto& [T, yaw_deg] = poses_[next_];
      if (arm.cameraPose().isApprox(T, 1e-9) || !arm.reachable(T)) continue;
      const double before_s = clock.now_s();
      const host::nbv::MoveResult move = arm.moveTo(T);
      tour.transit_s += clock.now_s() - before_s;
      move_status_ = host::nbv::toString(move.status);
      tour.transit_motion[move_status_] = tour.transit_motion.value(move_status_, 0) + 1;
      if (move.ok()) {
        entry["approach_distance_m"] = (T.translation() - cluster_.center_m).norm();
        entry["approach_yaw_deg"] = yaw_deg;
        ++next_;
        return true;
      }
    }
    return false;
  }

  /// The last move's status, "unreachable" when none was tried.
  const std::string& lastMoveStatus() const { return move_status_; }

 private:
  const FruitletCluster& cluster_;
  std::vector<ApproachPose> poses_;
  std::size_t next_ = 0;
  std::string move_status_ = "unreachable";
};

/// The perception of cluster k: in a world of several clusters only its own tag places a
/// Cluster Region (one cluster: any tag, as a grower's single tag).
host::PerceptionConfig perceptionFor(const World& world, std::size_t k) {
  host::PerceptionConfig perception;
  if (world.clusters().size() > 1) perception.tag.tag_id = world.clusters()[k].tag.tag_id;
  return perception;
}

nlohmann::json eventsJson(const host::nbv::NbvEvents& events) {
  return {{"planning_iterations", events.planning_iterations},
          {"iterations_without_move", events.iterations_without_move},
          {"move_attempts", events.move_attempts},
          {"failed_moves", events.failed_moves},
          {"candidates_rejected_clearance", events.rejected_clearance},
          {"gain_rays_culled", events.culled_rays},
          {"views_without_tag", events.views_without_tag},
          {"dropped_disparities", events.dropped_disparities},
          {"saturated_disparities", events.saturated_disparities},
          {"collision_voxels_freed_at_arm", events.obstacle_update_count},
          {"dropped_frames", events.dropped_frames},
          {"motion_status", events.motion_status}};
}

/// Adds every number of `part` into `total` (objects member by member, recursively).
void addNumbers(nlohmann::json& total, const nlohmann::json& part) {
  for (const auto& [key, value] : part.items()) {
    if (value.is_object()) {
      if (!total.contains(key)) total[key] = nlohmann::json::object();
      addNumbers(total[key], value);
    } else if (value.is_number_integer()) {
      total[key] = total.value(key, std::int64_t{0}) + value.get<std::int64_t>();
    } else if (value.is_number()) {
      total[key] = total.value(key, 0.0) + value.get<double>();
    }
  }
}

}  // namespace

/// What running the loop on one cluster gave.
struct ClusterOutcome {
  host::nbv::NbvResult run;
  nlohmann::json sizing;        ///< sizeAndScore's object
  nlohmann::json size_history;  ///< null unless sizes were kept after every view
  double sizing_wall_s = 0.0, sizing_during_loop_s = 0.0;
  /// With the automatic stop: what the sizing guidance did (added to the events).
  nlohmann::json guidance_events = nlohmann::json::object();
};

struct Trial::Impl {
  explicit Impl(TrialOptions opts) : options(std::move(opts)) {
    validate(options);
    completion_config.confirm_detections = options.confirm_detections;
    completion_config.release_left_out = options.release_left_out;
    if (!options.out_dir.empty()) {
      host::prepareOutputDirectory(options.out_dir, "trial output directory");
      lock.emplace(options.out_dir, "trial output directory");
      std::vector<std::string> stale = TrialParts::outputFiles();
      std::vector<std::string> subdirs = {"views", "overlays"};
      for (int k = 0; k < kMaxClusterDirs; ++k) {
        subdirs.push_back(clusterDirName(k));
        for (const std::string& file : TrialParts::clusterFiles())
          stale.push_back(clusterDirName(k) + "/" + file);
      }
      stale.push_back("viewer.html");
      // Every path the trial writes, before it runs: a `views` that is a file must not fail
      // the trial at its end.
      host::checkOutputPaths(options.out_dir, "trial output directory", stale, subdirs);
      host::removeStaleOutputs(options.out_dir, stale, {"views", "overlays"});
    }
    engine = options.engine.empty() ? defaultEngine(options.planner) : options.engine;

    // First: a missing backend or a bad planner config fails before the arm is built.
    backend = host::map::createBackendFor(engine, options.backend);
    const WorldConfig world_config = options.world_config.empty()
                                         ? WorldConfig{}
                                         : WorldConfig::fromYamlFile(options.world_config);
    world = std::make_unique<World>(World::generate(world_config, options.seed));
    // The first cluster's session and planner (maps + TSDF fed view by view, then sizing).
    parts = makeParts(0);

    // The simulated camera.
    RenderConfig render_config = renderConfigFor(world->config(), {}, options.seed);
    render_config.noise_seed = options.seed;
    renderer = std::make_unique<StereoRenderer>(*world, render_config);

    // The arm, its workspace tree and the simulated clock.
    if (!options.arm_config.empty()) arm_config = ArmConfig::fromYamlFile(options.arm_config);
    if (arm_config.workspace_cache_dir.empty()) arm_config.workspace_cache_dir = defaultCacheDir();
    arm = std::make_unique<ArmModel>(arm_config);
    workspace = std::make_unique<WorkspaceTree>(
        loadWorkspaceTree(*arm, [this](const std::string& text) { warn(text); }));
    clock = std::make_unique<SimClock>(SimClock::modeFromString(options.clock));
    const auto start = SimulatedArm::startConfiguration(*arm, world->startCameraPose());
    if (!start)
      throw std::runtime_error("world seed " + std::to_string(options.seed) +
                               ": the start view is out of the arm's reach");
    sim_arm = std::make_unique<SimulatedArm>(*arm, *workspace, *clock, *start);
    // A fixed clock is for runs that repeat: then the moves must repeat too.
    if (clock->mode() == SimClock::Mode::kFixed)
      sim_arm->setReproducibleMotionPlanning(options.seed);
    pose_errors = std::make_unique<PoseErrorModel>(world->config(), options.seed);
    wind = std::make_unique<WindModel>(*world, options.seed);
    segmentation = std::make_unique<SegmentationModel>(world->config(), options.seed);
    camera = std::make_unique<SimulatedCamera>(
        *renderer, *clock,
        SimulatedErrors{pose_errors->enabled() ? pose_errors.get() : nullptr,
                        wind->enabled() ? wind.get() : nullptr,
                        segmentation->enabled() ? segmentation.get() : nullptr});
  }

  // Cluster k's files go to out_dir/cluster_K (a world has at most 8 clusters).
  static constexpr int kMaxClusterDirs = 8;
  static std::string clusterDirName(std::size_t k) { return "cluster_" + std::to_string(k); }

  std::unique_ptr<TrialParts> makeParts(std::size_t k) const {
    // One cluster: the planner's seed is the trial's, as it always was.
    return std::make_unique<TrialParts>(options, engine, backend.get(), perceptionFor(*world, k),
                                        options.seed + k);
  }

  void warn(const std::string& text) {
    warnings.push_back(text);
    if (options.on_warning) options.on_warning(text);
  }

  /// The loop on one cluster from where the camera is, until the cluster's stop (its cap
  /// counted from t0_s), then its sizing scored against its fruitlets.
  ClusterOutcome runCluster(TrialParts& cluster_parts, const FruitletCluster& cluster,
                            host::nbv::Camera& loop_camera, host::nbv::Arm& loop_arm,
                            host::nbv::LoopClock& loop_clock, TrialLog& log);

  nlohmann::json run(host::nbv::Camera& loop_camera, host::nbv::Arm& loop_arm);
  nlohmann::json runTree(host::nbv::Camera& loop_camera, host::nbv::Arm& loop_arm);
  /// The tree's steps: a cluster's loop, retried from its next approach view while no view
  /// shows its tag; its entry and totals; its files and scene part; the result.
  ClusterOutcome runClusterFromApproaches(TrialParts& cluster_parts, const FruitletCluster& cluster,
                                          ApproachSequence& approach,
                                          host::nbv::Camera& loop_camera, host::nbv::Arm& loop_arm,
                                          host::nbv::LoopClock& loop_clock, TrialLog& log,
                                          nlohmann::json& entry, TourRecord& tour);
  void recordCluster(std::size_t k, TrialParts& cluster_parts, const ClusterOutcome& outcome,
                     const TrialLog& log, double sim_time_s, nlohmann::json& entry,
                     TourRecord& tour);
  void writeClusterOutputs(std::size_t k, TrialParts& cluster_parts, const ClusterOutcome& outcome,
                           const TrialLog& log, host::report::ViewerScene& scene, TourRecord& tour);
  void scoreSkippedClusters(TourRecord& tour, host::report::ViewerScene& scene) const;
  nlohmann::json treeResult(TourRecord& tour, host::report::ViewerScene& scene);
  /// The fields every result has: options, config, clock, logs, warnings.
  void describeRun(nlohmann::json& result, const TrialLog& log,
                   const std::vector<Eigen::Vector3d>& camera_path) const;
  /// result.json's "stop": the rule and, with --stop auto, its parameters.
  nlohmann::json stopJson() const;
  /// The overlays write() writes, or none and a warning when it fails: they are an extra that
  /// must not cost the run its result.
  nlohmann::json overlaysOrWarning(const std::function<nlohmann::json()>& write) {
    try {
      return write();
    } catch (const std::exception& e) {
      warn(std::string("overlays not drawn: ") + e.what());
      return nlohmann::json::array();
    }
  }
  /// The writer of the extras after result.json: a failure (a full disk) becomes a warning
  /// in result["warnings"] and the file's name in result["unwritten_outputs"]; a signal's stop
  /// is not caught. finishExtras writes result.json again with them.
  ExtraWriter extraWriter(nlohmann::json& result) {
    return [this, &result](const std::string& file, const std::function<void()>& write) {
      try {
        write();
      } catch (const host::Interrupted&) {
        throw;
      } catch (const std::exception& e) {
        const std::string text = file + " not written: " + e.what();
        result["warnings"].push_back(text);
        result["unwritten_outputs"].push_back(file);
        if (options.on_warning) options.on_warning(text);
      }
    };
  }
  /// views/NNN.png, viewer.html, then result.json again when an extra failed (best effort:
  /// the result written first stands when this fails too).
  void finishExtras(nlohmann::json& result, const TrialLog& log,
                    const std::function<void()>& write_viewer) {
    const ExtraWriter extra = extraWriter(result);
    extra("views", [&] {
      if (!log.viewPngs().empty()) std::filesystem::create_directories(options.out_dir / "views");
      for (const auto& [index, png] : log.viewPngs())
        if (!png.empty())
          host::writeFileAtomically(options.out_dir / host::numberedFileName("views", index, "png"),
                                    "view image", png);
    });
    extra("viewer.html", write_viewer);
    if (!result.contains("unwritten_outputs")) return;
    try {
      host::writeFileAtomically(options.out_dir / "result.json", "trial result",
                                result.dump(2) + "\n");
    } catch (const std::exception& e) {
      if (options.on_warning)
        options.on_warning(std::string("result.json kept without these warnings: ") + e.what());
    }
  }
  std::string viewerTitle() const {
    return (world->clusters().size() > 1 ? "Tree trial: " : "Trial: ") + options.planner +
           ", world seed " + std::to_string(options.seed);
  }

  TrialOptions options;
  /// One writer per output directory, for the trial's life.
  std::optional<host::OutputDirectoryLock> lock;
  /// The automatic stop's parameters, for every cluster (and the record of them).
  host::nbv::ClusterCompletionConfig completion_config;
  Clock::time_point wall_start = Clock::now();
  std::vector<std::string> warnings;
  std::string engine;
  std::unique_ptr<accel::Backend> backend;
  std::unique_ptr<World> world;
  std::unique_ptr<TrialParts> parts;
  std::unique_ptr<StereoRenderer> renderer;
  ArmConfig arm_config;
  std::unique_ptr<ArmModel> arm;
  std::unique_ptr<WorkspaceTree> workspace;
  std::unique_ptr<SimClock> clock;
  std::unique_ptr<PoseErrorModel> pose_errors;
  std::unique_ptr<WindModel> wind;
  std::unique_ptr<SegmentationModel> segmentation;
  std::unique_ptr<SimulatedCamera> camera;
  std::unique_ptr<SimulatedArm> sim_arm;
  bool ran = false;
};

ClusterOutcome Trial::Impl::runCluster(TrialParts& cluster_parts, const FruitletCluster& cluster,
                                       host::nbv::Camera& loop_camera, host::nbv::Arm& loop_arm,
                                       host::nbv::LoopClock& loop_clock, TrialLog& log) {
  const double t0_s = loop_clock.now_s();
  // The budget is a time on the run's clock: this cluster's cap from its arrival.
  host::nbv::StopCondition stop = host::nbv::StopCondition::budget(t0_s + options.budget_s);
  if (options.max_views) stop = stop || host::nbv::StopCondition::views(*options.max_views);
  host::nbv::LoopObservers observers;
  observers.add(&log);
  UnchargedClock observing_clock(loop_clock);  // before completion: it outlives it
  std::optional<host::nbv::ClusterCompletion> completion;
  std::optional<host::nbv::SizingGuidance> guidance;
  if (options.stop == "auto") {
    completion.emplace(cluster_parts.session(), loop_clock, cluster_parts.sizingConfig(),
                       completion_config);
    observers.add(&*completion);
    guidance.emplace(*completion, cluster_parts.planner(),
                     cluster_parts.sizingConfig().well_seen_fraction);
    observers.add(&*guidance);  // after completion: it reads completion's sizing
    completion->holdWhile([&g = *guidance] { return g.waitingOnUnconfirmed(); });
    if (completion_config.release_left_out)
      completion->releaseWhen(
          [&g = *guidance](const host::nbv::FruitletSnapshot& f) { return g.leftOut(f.center_m); });
    stop = stop || completion->stopCondition();
  } else if (options.record_size_history) {
    completion.emplace(cluster_parts.session(), observing_clock, cluster_parts.sizingConfig(),
                       completion_config);
    observers.add(&*completion);
  }
  host::nbv::NbvLoop loop(cluster_parts.session(), cluster_parts.planner(), loop_camera, loop_arm,
                          loop_clock);
  ClusterOutcome out;
  out.run = loop.run(stop, &observers);
  if (guidance) {
    out.guidance_events = {{"sizing_views", guidance->aimedViews()},
                           {"sizing_targets_dropped", guidance->droppedTargets()}};
    cluster_parts.planner().setSizingTargets({});  // this cluster's fruitlets
  }

  const auto t_size = Clock::now();
  out.sizing = cluster_parts.sizeAndScore(*world, cluster.fruitlet_indices);
  out.sizing_wall_s = secondsSince(t_size);
  if (completion) {
    for (const auto& snapshot : completion->history())
      out.sizing_during_loop_s += snapshot.sizing_s;
    out.size_history =
        sizeHistoryJson(completion->history(), *world, cluster.fruitlet_indices, t0_s);
  }
  return out;
}

nlohmann::json Trial::Impl::stopJson() const {
  if (options.stop != "auto") return {{"rule", "budget"}};
  const host::nbv::ClusterCompletionConfig& c = completion_config;
  return {{"rule", "auto"},
          {"stable_views", c.stable_views},
          {"size_tolerance_mm", c.size_tolerance_mm},
          {"tolerate_standard_error", c.tolerate_standard_error},
          {"same_fruitlet_m", c.same_fruitlet_m},
          {"min_well_seen_images", c.min_well_seen_images},
          {"min_view_span_deg", c.min_view_span_deg},
          {"max_iterations_without_view", c.max_iterations_without_view},
          {"confirm_detections", c.confirm_detections},
          {"release_left_out", c.release_left_out}};
}

void Trial::Impl::describeRun(nlohmann::json& result, const TrialLog& log,
                              const std::vector<Eigen::Vector3d>& camera_path) const {
  result["clock"] = nlohmann::json::parse(clock->toJson());
  result["register_views"] = options.register_views;
  result["view_log"] = log.views();
  result["plan_log"] = log.plans();
  nlohmann::json path = nlohmann::json::array();
  for (const auto& p : camera_path) path.push_back(vec3Json(p));
  result["camera_path_m"] = path;
  result["warnings"] = warnings;
}

nlohmann::json Trial::Impl::run(host::nbv::Camera& loop_camera, host::nbv::Arm& loop_arm) {
  if (ran) throw std::logic_error("Trial::run: a trial runs once (its world and clock are spent)");
  ran = true;
  if (world->clusters().size() > 1) return runTree(loop_camera, loop_arm);
  // The loop, driven through the camera, arm and clock like a robot's.
  SimulatedLoopClock loop_clock(*clock);
  TrialLog log(*camera, options, wall_start);
  log.setClusterCenter(world->clusterCenter_m());
  const ClusterOutcome outcome =
      runCluster(*parts, world->clusters().front(), loop_camera, loop_arm, loop_clock, log);
  const host::nbv::NbvResult& run = outcome.run;
  std::vector<Eigen::Vector3d> camera_path;
  for (const auto& T : run.camera_poses) camera_path.push_back(T.translation());

  nlohmann::json result;
  result["planner"] = options.planner;
  result["seed"] = options.seed;
  result["engine"] = engine;
  result["backend"] = backend ? std::string(accel::toString(backend->kind())) : "none";
  result["views"] = run.views;
  result["stop_reason"] = run.stop_reason;
  result["sim_time_s"] = clock->now_s();
  result["budget_s"] = options.budget_s;
  result["wall_time_s"] = secondsSince(wall_start);
  result["status"] = parts->map() ? "ok" : "no_tag";
  result["config"] = {{"planner", nlohmann::json::parse(parts->planner().configJson())},
                      {"arm", nlohmann::json::parse(arm_config.toJson())},
                      {"trial", parts->configJson()}};
  for (auto& [key, value] : outcome.sizing.items()) result[key] = value;
  result["events"] = eventsJson(run.events);
  result["events"].update(outcome.guidance_events);
  if (options.register_views)
    result["anchor_offset"] = anchorOffsetJson(parts->session(), log.trueAnchorShift());
  result["wall_breakdown_s"] = {{"rendering", camera->totalRenderSeconds()},
                                {"perception", run.wall_s.perception},
                                {"mapping", run.wall_s.mapping},
                                {"tsdf", run.wall_s.tsdf},
                                {"planning", run.wall_s.planning},
                                {"motion_planning", run.wall_s.motion_planning},
                                {"sizing", outcome.sizing_wall_s},
                                {"sizing_during_loop", outcome.sizing_during_loop_s}};
  if (!outcome.size_history.is_null()) result["size_history"] = outcome.size_history;
  result["stop"] = stopJson();
  if (!options.out_dir.empty())
    result["overlays"] = overlaysOrWarning([&] {
      return host::writeSessionOverlays(parts->session(), outcome.sizing, 0, std::nullopt,
                                        imageSource(log), options.out_dir, "start view");
    });
  describeRun(result, log, camera_path);
  markSizedViews(result["view_log"], outcome.sizing, 0, std::nullopt);
  if (!options.out_dir.empty()) {
    parts->writeOutputs(result, *world, camera_path, options.out_dir, options.on_warning,
                        extraWriter(result));
    finishExtras(result, log, [&] {
      host::report::ViewerScene scene(viewerTitle(), "");
      host::addSessionToScene(scene, parts->session(), outcome.sizing, 0, std::nullopt);
      writeTrialViewer(scene, result, log.intrinsics(), options.out_dir);
    });
  }
  return result;
}

// A tree: the clusters one after another, nearest start view next, on one clock and one
// coarse map (each cluster's session carries the map on to the next, which moves the fine
// map to its own region). A cluster whose start view the arm cannot reach is skipped and
// counted.
nlohmann::json Trial::Impl::runTree(host::nbv::Camera& loop_camera, host::nbv::Arm& loop_arm) {
  SimulatedLoopClock loop_clock(*clock);
  TrialLog log(*camera, options, wall_start);
  const std::vector<FruitletCluster>& clusters = world->clusters();
  std::vector<bool> visited(clusters.size(), false);
  std::unique_ptr<host::map::MapEngine> carried_map;
  std::unique_ptr<TrialParts> cluster_parts = std::move(parts);
  TourRecord tour;
  host::report::ViewerScene scene(viewerTitle(), "");
  for (std::size_t step = 0; step < clusters.size(); ++step) {
    const std::size_t k = nearestUnvisited(clusters, visited, loop_arm.cameraPose().translation());
    visited[k] = true;
    tour.order.push_back(k);
    const FruitletCluster& cluster = clusters[k];
    nlohmann::json entry = {{"index", k},
                            {"tag_id", cluster.tag.tag_id},
                            {"gt_fruitlets", cluster.fruitlet_indices.size()},
                            {"start_sim_s", loop_clock.now_s()}};
    // To its start view (the first cluster's is where the arm starts), or, where the arm
    // cannot stand there, the same view from farther out along its axis, then turned.
    ApproachSequence approach(cluster);
    if (!loop_arm.cameraPose().isApprox(cluster.T_world_start_camera, 1e-9) &&
        !approach.moveToNext(loop_arm, loop_clock, entry, tour)) {
      entry["move_status"] = approach.lastMoveStatus();
      const std::string status =
          approach.lastMoveStatus() == "unreachable" ? "unreachable" : "move_failed";
      entry["status"] = status;
      ++tour.cluster_status[status];
      tour.cluster_entries.push_back(entry);
      continue;
    }
    if (!cluster_parts) cluster_parts = makeParts(k);
    if (carried_map) cluster_parts->session().carryOnWith(std::move(carried_map));
    const double t0_s = loop_clock.now_s();
    log.startCluster(static_cast<int>(k), cluster.center_m);
    const ClusterOutcome outcome = runClusterFromApproaches(
        *cluster_parts, cluster, approach, loop_camera, loop_arm, loop_clock, log, entry, tour);
    recordCluster(k, *cluster_parts, outcome, log, loop_clock.now_s() - t0_s, entry, tour);
    if (!options.out_dir.empty()) writeClusterOutputs(k, *cluster_parts, outcome, log, scene, tour);
    tour.cluster_entries.push_back(entry);
    carried_map = std::move(cluster_parts->session()).releaseMap();
    cluster_parts.reset();
  }

  nlohmann::json result = treeResult(tour, scene);
  describeRun(result, log, tour.camera_path);
  for (const char* key : {"warnings", "unwritten_outputs"})
    for (const auto& item : tour.cluster_write_failures.value(key, nlohmann::json::array()))
      result[key].push_back(item);
  for (const auto& c : result["clusters"])
    if (c.contains("first_view"))
      markSizedViews(result["view_log"], c, c["first_view"].get<int>(), c["index"].get<int>());
  if (!options.out_dir.empty()) {
    writeTreeOutputs(result, *world, carried_map.get(), tour.camera_path, options.out_dir,
                     options.on_warning, extraWriter(result));
    finishExtras(result, log, [&] {
      if (!tour.scene_error.empty()) throw std::runtime_error(tour.scene_error);
      writeTrialViewer(scene, result, log.intrinsics(), options.out_dir);
    });
  }
  return result;
}

// A view that shows no tag (a leaf before it from there, foliage an earlier cluster's views
// put on the way) places no Cluster Region: the next approach view may show it. The views
// taken on the way are the cluster's too.
ClusterOutcome Trial::Impl::runClusterFromApproaches(
    TrialParts& cluster_parts, const FruitletCluster& cluster, ApproachSequence& approach,
    host::nbv::Camera& loop_camera, host::nbv::Arm& loop_arm, host::nbv::LoopClock& loop_clock,
    TrialLog& log, nlohmann::json& entry, TourRecord& tour) {
  ClusterOutcome outcome =
      runCluster(cluster_parts, cluster, loop_camera, loop_arm, loop_clock, log);
  std::vector<Eigen::Isometry3d> untagged_poses;  // one per untagged view
  int retried_approaches = 0;
  while (!cluster_parts.map() && outcome.run.stop_reason == "no_region" &&
         approach.moveToNext(loop_arm, loop_clock, entry, tour)) {
    untagged_poses.insert(untagged_poses.end(), outcome.run.camera_poses.begin(),
                          outcome.run.camera_poses.end());
    ++retried_approaches;
    outcome = runCluster(cluster_parts, cluster, loop_camera, loop_arm, loop_clock, log);
  }
  outcome.run.views += untagged_poses.size();
  outcome.run.camera_poses.insert(outcome.run.camera_poses.begin(), untagged_poses.begin(),
                                  untagged_poses.end());
  entry["approaches_without_tag"] = retried_approaches;
  return outcome;
}

// One visited cluster into its entry and the tour's totals.
void Trial::Impl::recordCluster(std::size_t k, TrialParts& cluster_parts,
                                const ClusterOutcome& outcome, const TrialLog& log,
                                double sim_time_s, nlohmann::json& entry, TourRecord& tour) {
  const bool mapped = cluster_parts.map() != nullptr;
  if (options.register_views)
    entry["anchor_offset"] = anchorOffsetJson(cluster_parts.session(), log.trueAnchorShift());
  entry["status"] = mapped ? "sized" : "no_tag";
  ++tour.cluster_status[entry["status"].get<std::string>()];
  entry["views"] = outcome.run.views;
  entry["first_view"] = log.firstView();  // the run's number of its first view
  entry["stop_reason"] = outcome.run.stop_reason;
  entry["sim_time_s"] = sim_time_s;
  for (auto& [key, value] : outcome.sizing.items()) {
    if (key.rfind("fruitlets", 0) == 0) {
      // Every scored fruitlet says which cluster it is in.
      nlohmann::json tagged = value;
      for (auto& f : tagged) f["cluster"] = k;
      for (const auto& f : tagged) tour.scored[key].push_back(f);
      entry[key] = std::move(tagged);
    } else if (key == "detections" || key.rfind("metrics", 0) == 0 || key == "sizing_estimator" ||
               key == "unsupported_detections" || key == "sized_fruitlets" ||
               key == "sizing_stats") {
      entry[key] = value;
    }
  }
  tour.detections += outcome.sizing.value("detections", std::uint64_t{0});
  tour.views += outcome.run.views;
  entry["events"] = eventsJson(outcome.run.events);
  entry["events"].update(outcome.guidance_events);
  addNumbers(tour.events, entry["events"]);
  addNumbers(tour.wall, {{"perception", outcome.run.wall_s.perception},
                         {"mapping", outcome.run.wall_s.mapping},
                         {"tsdf", outcome.run.wall_s.tsdf},
                         {"planning", outcome.run.wall_s.planning},
                         {"motion_planning", outcome.run.wall_s.motion_planning},
                         {"sizing", outcome.sizing_wall_s},
                         {"sizing_during_loop", outcome.sizing_during_loop_s}});
  if (!outcome.size_history.is_null()) entry["size_history"] = outcome.size_history;
  for (const auto& T : outcome.run.camera_poses) tour.camera_path.push_back(T.translation());
  tour.planner_config = nlohmann::json::parse(cluster_parts.planner().configJson());
  tour.trial_config = cluster_parts.configJson();
}

// Written as the tour goes (the map moves on); a failure is recorded with the tree's result,
// not the end of the tour.
void Trial::Impl::writeClusterOutputs(std::size_t k, TrialParts& cluster_parts,
                                      const ClusterOutcome& outcome, const TrialLog& log,
                                      host::report::ViewerScene& scene, TourRecord& tour) {
  const ExtraWriter record = extraWriter(tour.cluster_write_failures);
  cluster_parts.writeClusterFiles(options.out_dir / clusterDirName(k),
                                  [&](const std::string& file, const std::function<void()>& write) {
                                    record(clusterDirName(k) + "/" + file, write);
                                  });
  const int cluster = static_cast<int>(k);
  // The scene's part of this cluster now: its map moves on to the next cluster.
  try {
    host::addSessionToScene(scene, cluster_parts.session(), outcome.sizing, log.firstView(),
                            cluster);
  } catch (const std::exception& e) {
    tour.scene_error = e.what();
  }
  for (auto& o : overlaysOrWarning([&] {
         return host::writeSessionOverlays(cluster_parts.session(), outcome.sizing, log.firstView(),
                                           cluster, imageSource(log), options.out_dir,
                                           "start view");
       }))
    tour.overlays.push_back(std::move(o));
}

// Every cluster's fruitlets, scored against its own ground truth, and the pooled metrics (a
// skipped cluster's fruitlets are in them, not matched).
void Trial::Impl::scoreSkippedClusters(TourRecord& tour, host::report::ViewerScene& scene) const {
  for (const auto& c : tour.cluster_entries) {
    if (c.contains("fruitlets")) continue;
    const auto& indices = world->clusters()[c.at("index").get<std::size_t>()].fruitlet_indices;
    nlohmann::json cluster_missed = nlohmann::json::array();
    for (const auto& g : groundTruthOf(*world, indices)) {
      const nlohmann::json missed = {{"gt_center_m", vec3Json(g.center_m)},
                                     {"gt_size_mm", g.size_mm},
                                     {"matched", false},
                                     {"est_center_m", nullptr},
                                     {"est_size_mm", nullptr},
                                     {"cluster", c.at("index")}};
      tour.scored["fruitlets"].push_back(missed);
      for (const char* other : {"fruitlets_paper_sizing", "fruitlets_ours_sizing"})
        if (tour.scored.contains(other)) tour.scored[other].push_back(missed);
      cluster_missed.push_back(missed);
    }
    // The viewer shows a skipped cluster's fruitlets too, none matched.
    scene.addSizing({{"fruitlets", cluster_missed}}, 0, c.at("index").get<int>());
  }
}

// The tree's result.json before describeRun: the tour's totals, every cluster's entry and
// the pooled metrics.
nlohmann::json Trial::Impl::treeResult(TourRecord& tour, host::report::ViewerScene& scene) {
  nlohmann::json result;
  result["planner"] = options.planner;
  result["seed"] = options.seed;
  result["engine"] = engine;
  result["backend"] = backend ? std::string(accel::toString(backend->kind())) : "none";
  result["views"] = tour.views;
  result["stop_reason"] = "tour_done";
  result["sim_time_s"] = clock->now_s();
  result["budget_s"] = options.budget_s;
  result["wall_time_s"] = secondsSince(wall_start);
  result["status"] = tour.cluster_status["sized"] > 0 ? "ok" : "no_tag";
  result["config"] = {{"planner", tour.planner_config},
                      {"arm", nlohmann::json::parse(arm_config.toJson())},
                      {"trial", tour.trial_config}};
  scoreSkippedClusters(tour, scene);
  if (!tour.scored.contains("fruitlets")) tour.scored["fruitlets"] = nlohmann::json::array();
  for (const auto& [key, fruitlets] : tour.scored.items()) {
    result[key] = fruitlets;
    result["metrics" + key.substr(std::string("fruitlets").size())] =
        host::eval::pooledMetricsJson(fruitlets, tour.detections);
  }
  result["detections"] = tour.detections;
  if (!tour.cluster_entries.empty() && tour.cluster_entries.back().contains("sizing_estimator"))
    result["sizing_estimator"] = tour.cluster_entries.back()["sizing_estimator"];
  result["clusters"] = tour.cluster_entries;
  result["tour"] = {{"order", tour.order},
                    {"cluster_status", tour.cluster_status},
                    {"transit_sim_s", tour.transit_s},
                    {"transit_motion_status", tour.transit_motion}};
  result["events"] = tour.events.empty() ? eventsJson({}) : tour.events;
  tour.wall["rendering"] = camera->totalRenderSeconds();
  result["wall_breakdown_s"] = tour.wall;
  result["stop"] = stopJson();
  if (!options.out_dir.empty()) result["overlays"] = tour.overlays;
  return result;
}

Trial::Trial(TrialOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}
Trial::~Trial() = default;

host::nbv::Camera& Trial::simulatedCamera() {
  return *impl_->camera;
}

host::nbv::Arm& Trial::simulatedArm() {
  return *impl_->sim_arm;
}

nlohmann::json Trial::run() {
  return impl_->run(*impl_->camera, *impl_->sim_arm);
}

nlohmann::json Trial::run(host::nbv::Camera& camera, host::nbv::Arm& arm) {
  return impl_->run(camera, arm);
}

nlohmann::json runTrial(const TrialOptions& options) {
  return Trial(options).run();
}

}  // namespace fvp::trials

namespace fvp::trials {

std::string trialSummary(const nlohmann::json& result) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1);
  s << "planner " << result.value("planner", "?") << ", world seed " << result.value("seed", 0)
    << ", engine " << result.value("engine", "?") << ", backend " << result.value("backend", "?")
    << "\n"
    << "views " << result.value("views", 0) << ", simulated " << result.value("sim_time_s", 0.0)
    << " s of " << result.value("budget_s", 0.0) << " s, wall " << result.value("wall_time_s", 0.0)
    << " s, stop: " << result.value("stop_reason", "?") << "\n";
  if (result.contains("clusters")) {
    s << "\n cluster  tag  status        views  simulated (s)  stop               matched\n";
    for (const auto& c : result["clusters"]) {
      std::size_t matched = 0;
      if (c.contains("fruitlets"))
        for (const auto& f : c["fruitlets"]) matched += f.value("matched", false);
      s << std::setw(8) << c.value("index", 0) << std::setw(5) << c.value("tag_id", 0) << "  "
        << std::left << std::setw(12) << c.value("status", "?") << std::right << std::setw(7)
        << c.value("views", 0) << std::setw(15) << std::setprecision(1)
        << c.value("sim_time_s", 0.0) << "  " << std::left << std::setw(19)
        << c.value("stop_reason", "-") << std::right << matched << " of "
        << c.value("gt_fruitlets", 0) << "\n";
    }
  }
  if (result.contains("fruitlets")) {
    s << "\n fruitlet  true (mm)  estimated (mm)  error (mm)\n";
    int i = 0;
    for (const auto& f : result["fruitlets"]) {
      s << std::setw(9) << i++ << std::setw(11) << std::setprecision(2)
        << f.value("gt_size_mm", 0.0);
      if (f.value("matched", false))
        s << std::setw(16) << f.value("est_size_mm", 0.0) << std::setw(12)
          << f.value("est_size_mm", 0.0) - f.value("gt_size_mm", 0.0) << "\n";
      else
        s << std::setw(16) << "not matched"
          << "\n";
    }
  }
  if (result.contains("metrics")) {
    const auto& m = result["metrics"];
    const auto num = [&](const char* key, int precision) {
      std::ostringstream v;
      if (m.contains(key) && m[key].is_number())
        v << std::fixed << std::setprecision(precision) << m[key].get<double>();
      else
        v << "-";
      return v.str();
    };
    s << "\nmatch " << num("match_percent", 1) << " %, MAE " << num("mae_mm", 2) << " mm, MAPE "
      << num("mape_percent", 1) << " %, detections " << result.value("detections", 0) << "\n";
  }
  return s.str();
}

}  // namespace fvp::trials
