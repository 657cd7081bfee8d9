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
#include "fvp/host/report/session_report.h"
#include "fvp/host/report/viewer_scene.h"
#include "fvp/host/season/remembered_visit.h"
#include "fvp/host/session/mapping_session.h"
#include "fvp/robot/arm_model.h"
#include "fvp/robot/sim/simulated_arm.h"
#include "fvp/robot/sim/simulated_camera.h"
#include "fvp/robot/sim/simulated_loop_clock.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/world.h"
#include "fvp/robot/workspace_tree.h"
#include "fvp/trials/experiment_directory.h"
#include "fvp/trials/simulated_robot.h"
#include "fvp/trials/trial_fields.h"
#include "trial_parts.h"
#include "trial_report.h"
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
                                const std::optional<Eigen::Vector3d>& true_anchor_error_m,
                                const std::optional<Eigen::Vector3d>& true_frame_error_m) {
  const host::AnchorOffset offset = session.anchorOffset();
  nlohmann::json j = {{"shift_mm", vec3Json(1000.0 * offset.shift_m)},
                      {"hand_eye_mm", vec3Json(1000.0 * offset.hand_eye_m)},
                      {"views", offset.views},
                      {"valid", offset.valid},
                      {"applied", session.correctsAnchorOffset() && offset.valid}};
  if (const host::ClusterPoseGraph* graph = session.poseGraph()) {
    nlohmann::json disagreeing = nlohmann::json::array();
    std::size_t tag_views = 0;
    for (std::size_t k = 0; k < graph->size(); ++k) {
      if (graph->estimate(k).disagrees) disagreeing.push_back(k);
      tag_views += graph->view(k).tag.has_value();
    }
    j["pose_graph"] = {{"views", graph->size()},
                       {"tag_views", tag_views},
                       {"disagreeing_views", disagreeing},
                       {"tsdf_refusions", session.tsdfRefusions()}};
  }
  if (true_anchor_error_m) {
    j["anchor_error_mm"] = 1000.0 * true_anchor_error_m->norm();
    j["corrected_error_mm"] = 1000.0 * (*true_anchor_error_m - offset.shift_m).norm();
  }
  if (true_frame_error_m) {
    j["frame_error_mm"] = 1000.0 * true_frame_error_m->norm();
    j["corrected_frame_error_mm"] = 1000.0 * (*true_frame_error_m - offset.shift_m).norm();
  }
  return j;
}

/// R_world_camera as [w, x, y, z]; the camera looks along its z axis (OpenCV frame).
nlohmann::json quaternionWxyz(const Eigen::Isometry3d& T) {
  return host::report::poseJson(T).at("quaternion_wxyz");
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
    placed_errors_m_.clear();
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
        // Where the view's points were fused, off the truth: the maps' frame error as this
        // view carries it (the same in every view when the views agree).
        const Eigen::Vector3d placed =
            shift - (v.registration ? v.registration->placement_m : Eigen::Vector3d::Zero());
        views_.back()["placed_error_mm"] = vec3Json(1000.0 * placed);
        placed_errors_m_.push_back(placed);
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
          {"pairs", r.pairs},
          {"placement_mm", vec3Json(1000.0 * r.placement_m)}};
      if (r.predicted_m)
        views_.back()["registration"]["predicted_mm"] = vec3Json(1000.0 * *r.predicted_m);
    }
    if (!options_.out_dir.empty()) {
      view_pngs_.emplace_back(index, encodeViewImage(index, *e.frame));
      images_.add(index, e.frame->left_bgr);
      if (!intrinsics_) intrinsics_ = e.frame->intrinsics;
    }
    if (options_.on_progress)
      options_.on_progress({index + 1, e.now_s, options_.budget_s, secondsSince(wall_start_)});
    if (options_.on_frame && e.frame) options_.on_frame(*e.frame, e.now_s);
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
         {"ended_by_failed_plans", step.gave_up},
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
  std::optional<Eigen::Vector3d> trueAnchorShift() const { return meanOf(anchor_shifts_m_); }
  /// With pose errors: the fused maps' true frame error at the cluster's centre, the mean of
  /// the views' placed errors (what the reported shift should be).
  std::optional<Eigen::Vector3d> trueFrameError() const { return meanOf(placed_errors_m_); }
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
  static std::optional<Eigen::Vector3d> meanOf(const std::vector<Eigen::Vector3d>& shifts_m) {
    if (shifts_m.empty()) return std::nullopt;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const auto& d : shifts_m) sum += d;
    return sum / double(shifts_m.size());
  }

  int cluster_ = -1, first_view_ = 0;  ///< -1: a one-cluster world
  std::optional<Eigen::Vector3d> cluster_center_m_;
  std::vector<Eigen::Vector3d> anchor_shifts_m_;
  std::vector<Eigen::Vector3d> placed_errors_m_;
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
                   {"sized_any_image", snapshot.sized_any_image},
                   {"fruitlets", fruitlets},
                   {"match_percent", m.match_percent},
                   {"mae_mm", opt(m.mae_mm)},
                   {"precision_percent", opt(m.precision_percent)}});
  }
  return out;
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
  double transit_s = 0.0, transit_motion_s = 0.0;
  nlohmann::json planner_config, trial_config;
  std::string scene_error;  // why the scene could not be built (no viewer then)
  nlohmann::json overlays = nlohmann::json::array();
};

nlohmann::json eventsJson(const host::nbv::NbvEvents& events) {
  return {{"planning_iterations", events.planning_iterations},
          {"iterations_without_move", events.iterations_without_move},
          {"move_attempts", events.move_attempts},
          {"failed_moves", events.failed_moves},
          {"candidates_rejected_clearance", events.rejected_clearance},
          {"goal_checks", events.goal_checks},
          {"goal_check_batches", events.goal_check_batches},
          {"candidates_rejected_no_ik", events.rejected_no_ik},
          {"candidates_rejected_no_collision_free_ik", events.rejected_no_collision_free_ik},
          {"gain_rays_culled", events.culled_rays},
          {"views_without_tag", events.views_without_tag},
          {"dropped_disparities", events.dropped_disparities},
          {"saturated_disparities", events.saturated_disparities},
          {"collision_voxels_freed_at_arm", events.obstacle_update_count},
          {"iterations_ended_by_failed_plans", events.iterations_ended_by_failed_plans},
          {"retreats", events.retreats},
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

/// What running the loop on one cluster gave, scored.
struct ClusterOutcome {
  host::nbv::NbvResult run;
  nlohmann::json sizing;        ///< TrialParts::score's object
  nlohmann::json size_history;  ///< null unless sizes were kept after every view
  double sizing_wall_s = 0.0, sizing_during_loop_s = 0.0;
  /// With the automatic stop: what the sizing guidance did (added to the events).
  nlohmann::json guidance_events = nlohmann::json::object();
  /// With a remembered visit: what the cluster's memory did (null without one).
  nlohmann::json memory;
};

namespace {

/// The library's setup of a trial's options.
host::nbv::NbvSetupOptions setupOptions(const TrialOptions& o) {
  host::nbv::NbvSetupOptions s;
  s.planner = o.planner;
  s.planner_config = o.planner_config;
  s.engine = o.engine;
  s.backend = o.backend;
  s.planner_seed = o.seed;  // cluster k: seed + k (one cluster: the trial's seed)
  s.register_views = o.register_views.value_or(false);
  s.stop.rule = o.stop;
  s.stop.budget_s = o.budget_s;
  s.stop.max_views = o.max_views;
  s.stop.record_size_history = o.record_size_history;
  s.stop.completion.confirm_detections = o.confirm_detections;
  s.stop.completion.seek_partly_seen = o.seek_partly_seen;
  s.stop.completion.release_left_out = o.release_left_out;
  s.stop.completion.known_fruitlets = o.known_fruitlets;
  s.disparity_window = o.disparity_window;
  s.guided_stereo = o.guided_stereo;
  s.loop.view_overhead_s = o.view_overhead_s;
  return s;
}

}  // namespace

struct Trial::Impl {
  class TourRecorder;

  explicit Impl(TrialOptions opts) : options(std::move(opts)) {
    // The setup's checks, before the output directory is touched.
    setupOptions(options).validate();
    options.register_views = registerViewsOf(options);
    const std::map<int, host::nbv::ClusterMemory> memory = readMemory();
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
    // First: a missing backend or a bad planner config fails before the arm is built.
    setup = std::make_unique<host::nbv::NbvSetup>(setupOptions(options));
    SimulatedRobotOptions sim;
    sim.seed = options.seed;
    sim.world_config = options.world_config;
    sim.season_day = options.season_day;
    sim.arm_config = options.arm_config;
    sim.clock = options.clock;
    sim.fixed_perception_time_s = robot::sim::fixedPerceptionTimeS(options.guided_stereo);
    sim.on_warning = [this](const std::string& text) { warn(text); };
    robot = std::make_unique<SimulatedRobot>(sim);
    world = &robot->world();
    camera = &robot->camera();
    targets = robot->clusterTargets();
    remember(memory);
  }

  /// The remembered visit's clusters (read before out_dir is cleared: it may be the same).
  std::map<int, host::nbv::ClusterMemory> readMemory() const {
    if (options.remembered_visit.empty()) return {};
    const host::nbv::ClusterCompletionConfig stop = setupOptions(options).stop.completion;
    return host::season::readVisitMemory(options.remembered_visit,
                                         {stop.min_well_seen_images, stop.min_view_span_deg});
  }

  /// Each cluster's memory by its tag (a world of one cluster: the result's one cluster).
  void remember(const std::map<int, host::nbv::ClusterMemory>& memory) {
    for (std::size_t k = 0; k < targets.size(); ++k) {
      const auto found = targets.size() == 1 && memory.size() == 1
                             ? memory.begin()
                             : memory.find(world->clusters()[k].tag.tag_id);
      if (found != memory.end()) targets[k].memory = found->second;
    }
  }

  // Cluster k's files go to out_dir/cluster_K (a world has at most 8 clusters).
  static constexpr int kMaxClusterDirs = 8;
  static std::string clusterDirName(std::size_t k) { return "cluster_" + std::to_string(k); }

  void warn(const std::string& text) {
    warnings.push_back(text);
    if (options.on_warning) options.on_warning(text);
  }

  /// A cluster's run through the library, scored against its fruitlets (size_history's
  /// times from the start of its last loop).
  ClusterOutcome scored(host::nbv::ClusterRun run, TrialParts& cluster_parts,
                        const FruitletCluster& cluster) const;

  nlohmann::json run(host::nbv::Camera& loop_camera, host::nbv::Arm& loop_arm);
  nlohmann::json runTree(host::nbv::Camera& loop_camera, host::nbv::Arm& loop_arm);
  /// The tree's steps: a visited cluster's entry and totals; its files and scene part; a
  /// skipped cluster's entry; the result.
  void recordCluster(const host::nbv::ClusterVisit& visit, TrialParts& cluster_parts,
                     const ClusterOutcome& outcome, const TrialLog& log, nlohmann::json& entry,
                     TourRecord& tour);
  void writeClusterOutputs(std::size_t k, const TrialParts& cluster_parts,
                           const ClusterOutcome& outcome, const TrialLog& log,
                           host::report::ViewerScene& scene, TourRecord& tour);
  nlohmann::json clusterEntry(const host::nbv::ClusterVisit& visit) const;
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
  std::string backendName() const {
    return setup->backend() ? std::string(accel::toString(setup->backend()->kind())) : "none";
  }

  TrialOptions options;
  /// One writer per output directory, for the trial's life.
  std::optional<host::OutputDirectoryLock> lock;
  Clock::time_point wall_start = Clock::now();
  std::vector<std::string> warnings;
  /// The library's run: sessions, planners, the stop and the tour.
  std::unique_ptr<host::nbv::NbvSetup> setup;
  /// The simulator: world, camera, arm, clock.
  std::unique_ptr<SimulatedRobot> robot;
  /// The robot's clusters, with what the remembered visit learned of each.
  std::vector<host::nbv::ClusterTarget> targets;
  const World* world = nullptr;
  const SimulatedCamera* camera = nullptr;
  bool ran = false;
};

ClusterOutcome Trial::Impl::scored(host::nbv::ClusterRun run, TrialParts& cluster_parts,
                                   const FruitletCluster& cluster) const {
  ClusterOutcome out;
  out.run = std::move(run.run);
  out.sizing_wall_s = run.sizing_wall_s;
  out.sizing_during_loop_s = run.sizing_during_loop_s;
  out.sizing = cluster_parts.score(std::move(run.sizing), setup->options().sizing.estimator, *world,
                                   cluster.fruitlet_indices, cluster.tag.T_world_tag);
  const bool automatic = options.stop == host::nbv::StopRule::kAuto;
  if (automatic || options.record_size_history)
    out.size_history =
        sizeHistoryJson(run.size_history, *world, cluster.fruitlet_indices, run.start_s);
  if (automatic)
    out.guidance_events = {{"sizing_views", run.sizing_views},
                           {"sizing_targets_dropped", run.sizing_targets_dropped}};
  if (run.memory)
    out.memory = {{"views", run.memory->views},         {"views_taken", run.memory->views_taken},
                  {"fruitlets", run.memory->fruitlets}, {"found", run.memory->found},
                  {"gone", run.memory->gone},           {"known", run.memory->known}};
  return out;
}

nlohmann::json Trial::Impl::stopJson() const {
  if (options.stop != host::nbv::StopRule::kAuto)
    return {{"rule", host::nbv::toString(options.stop)}};
  const host::nbv::ClusterCompletionConfig& c = setup->options().stop.completion;
  return {{"rule", "auto"},
          {"stable_views", c.stable_views},
          {"size_tolerance_mm", c.size_tolerance_mm},
          {"tolerate_standard_error", c.tolerate_standard_error},
          {"same_fruitlet_m", c.same_fruitlet_m},
          {"min_well_seen_images", c.min_well_seen_images},
          {"min_view_span_deg", c.min_view_span_deg},
          {"min_stable_span_deg", c.min_stable_span_deg},
          {"max_iterations_without_view", c.max_iterations_without_view},
          {"confirm_detections", c.confirm_detections},
          {"seek_partly_seen", c.seek_partly_seen},
          {"release_left_out", c.release_left_out},
          {"known_fruitlets", c.known_fruitlets},
          {"known_stable_views", c.known_stable_views}};
}

void Trial::Impl::describeRun(nlohmann::json& result, const TrialLog& log,
                              const std::vector<Eigen::Vector3d>& camera_path) const {
  result["clock"] = nlohmann::json::parse(robot->clock().toJson());
  // What the clock charges: a season resumes only visits timed by this build's clock.
  result["clock_charges"] = ExperimentManifest::clockChargesFor(options.guided_stereo);
  if (!options.remembered_visit.empty())
    result["remembered_visit"] = options.remembered_visit.string();
  // The clock's record stays in result.json only; its sums by stage go everywhere the trial
  // does (an experiment's trials.jsonl, where its time split is pooled).
  result["sim_time_by_stage_s"] = simulatedSecondsByStage(result["clock"]);
  result["register_views"] = *options.register_views;
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
  host::nbv::LoopClock& loop_clock = robot->loopClock();
  TrialLog log(*camera, options, wall_start);
  log.setClusterCenter(world->clusterCenter_m());
  const std::unique_ptr<host::nbv::ClusterWork> work = setup->makeWork(targets.front());
  TrialParts parts(options, setup->engine(), *work);
  const ClusterOutcome outcome =
      scored(setup->runCluster({loop_camera, loop_arm, loop_clock}, *work, &log), parts,
             world->clusters().front());
  const host::nbv::NbvResult& run = outcome.run;
  std::vector<Eigen::Vector3d> camera_path;
  for (const auto& T : run.camera_poses) camera_path.push_back(T.translation());

  nlohmann::json result;
  result["settings"] = trialSettingsJson(options);
  result["planner"] = options.planner;
  result["seed"] = options.seed;
  result["engine"] = setup->engine();
  result["backend"] = backendName();
  result["views"] = run.views;
  result["stop_reason"] = run.stop_reason;
  result["sim_time_s"] = robot->clock().now_s();
  result["budget_s"] = options.budget_s;
  result["wall_time_s"] = secondsSince(wall_start);
  result["status"] = parts.session().map() ? "ok" : "no_tag";
  result["config"] = {{"planner", nlohmann::json::parse(parts.planner().configJson())},
                      {"arm", nlohmann::json::parse(robot->armConfig().toJson())},
                      {"trial", parts.configJson(setup->options().sizing)}};
  for (auto& [key, value] : outcome.sizing.items()) result[key] = value;
  result["events"] = eventsJson(run.events);
  result["events"].update(outcome.guidance_events);
  if (!outcome.memory.is_null()) result["memory"] = outcome.memory;
  if (*options.register_views)
    result["anchor_offset"] =
        anchorOffsetJson(parts.session(), log.trueAnchorShift(), log.trueFrameError());
  result["wall_breakdown_s"] = {{"rendering", camera->totalRenderSeconds()},
                                {"perception", run.wall_s.perception},
                                {"mapping", run.wall_s.mapping},
                                {"tsdf", run.wall_s.tsdf},
                                {"planning", run.wall_s.planning},
                                {"goal_check", run.wall_s.goal_check},
                                {"motion_planning", run.wall_s.motion_planning},
                                {"sizing", outcome.sizing_wall_s},
                                {"sizing_during_loop", outcome.sizing_during_loop_s}};
  if (!outcome.size_history.is_null()) result["size_history"] = outcome.size_history;
  result["stop"] = stopJson();
  if (!options.out_dir.empty())
    result["overlays"] = overlaysOrWarning([&] {
      return host::writeSessionOverlays(parts.session(), outcome.sizing, 0, std::nullopt,
                                        imageSource(log), options.out_dir, "start view");
    });
  describeRun(result, log, camera_path);
  markSizedViews(result["view_log"], outcome.sizing, 0, std::nullopt);
  if (!options.out_dir.empty()) {
    parts.writeOutputs(result, *world, camera_path, options.out_dir, options.on_warning,
                       extraWriter(result));
    finishExtras(result, log, [&] {
      host::report::ViewerScene scene(viewerTitle(), "");
      host::addSessionToScene(scene, parts.session(), outcome.sizing, 0, std::nullopt);
      writeTrialViewer(scene, result, log.intrinsics(), options.out_dir);
    });
  }
  return result;
}

/// A tree's tour as the trial hears of it: views and plans into the log, each cluster
/// scored, recorded and written as it is finished (before its map moves on).
class Trial::Impl::TourRecorder : public host::nbv::TourObserver {
 public:
  TourRecorder(Trial::Impl& trial, TrialLog& log, TourRecord& tour,
               host::report::ViewerScene& scene)
      : trial_(trial), log_(log), tour_(tour), scene_(scene) {}

  void onView(const host::nbv::ViewEvent& e) override { log_.onView(e); }
  void onPlan(const host::nbv::PlanEvent& e) override { log_.onPlan(e); }
  void onDroppedFrame(const std::string& detail) override { log_.onDroppedFrame(detail); }
  void onClusterStart(std::size_t index, const host::nbv::ClusterTarget& target) override {
    log_.startCluster(static_cast<int>(index), target.center_m);
  }
  void onClusterDone(const host::nbv::ClusterVisit& visit,
                     const host::nbv::ClusterWork& work) override {
    const std::size_t k = visit.index;
    TrialParts parts(trial_.options, trial_.setup->engine(), work);
    const ClusterOutcome outcome = trial_.scored(*visit.run, parts, trial_.world->clusters()[k]);
    nlohmann::json entry = trial_.clusterEntry(visit);
    trial_.recordCluster(visit, parts, outcome, log_, entry, tour_);
    if (!trial_.options.out_dir.empty())
      trial_.writeClusterOutputs(k, parts, outcome, log_, scene_, tour_);
    tour_.cluster_entries.push_back(entry);
  }
  void onClusterSkipped(const host::nbv::ClusterVisit& visit) override {
    nlohmann::json entry = trial_.clusterEntry(visit);
    entry["move_status"] = visit.move_status;
    entry["status"] = host::nbv::toString(visit.status);
    ++tour_.cluster_status[host::nbv::toString(visit.status)];
    tour_.cluster_entries.push_back(entry);
  }

 private:
  Trial::Impl& trial_;
  TrialLog& log_;
  TourRecord& tour_;
  host::report::ViewerScene& scene_;
};

// A tree: the library's tour (the clusters one after another on one clock and one coarse
// map), each cluster scored against its fruitlets as it is finished.
nlohmann::json Trial::Impl::runTree(host::nbv::Camera& loop_camera, host::nbv::Arm& loop_arm) {
  host::nbv::LoopClock& loop_clock = robot->loopClock();
  TrialLog log(*camera, options, wall_start);
  TourRecord tour;
  host::report::ViewerScene scene(viewerTitle(), "");
  TourRecorder recorder(*this, log, tour, scene);
  const host::nbv::TourResult done =
      setup->runTour({loop_camera, loop_arm, loop_clock}, targets, &recorder);
  for (const auto& visit : done.visits) tour.order.push_back(visit.index);
  tour.transit_s = done.transit_s;
  tour.transit_motion_s = done.transit_motion_s;
  for (const auto& [status, count] : done.transit_motion) tour.transit_motion[status] = count;

  nlohmann::json result = treeResult(tour, scene);
  describeRun(result, log, tour.camera_path);
  for (const char* key : {"warnings", "unwritten_outputs"})
    for (const auto& item : tour.cluster_write_failures.value(key, nlohmann::json::array()))
      result[key].push_back(item);
  for (const auto& c : result["clusters"])
    if (c.contains("first_view"))
      markSizedViews(result["view_log"], c, c["first_view"].get<int>(), c["index"].get<int>());
  if (!options.out_dir.empty()) {
    writeTreeOutputs(result, *world, done.map.get(), tour.camera_path, options.out_dir,
                     options.on_warning, extraWriter(result));
    finishExtras(result, log, [&] {
      if (!tour.scene_error.empty()) throw std::runtime_error(tour.scene_error);
      writeTrialViewer(scene, result, log.intrinsics(), options.out_dir);
    });
  }
  return result;
}

// A cluster's entry as the tour reached it.
nlohmann::json Trial::Impl::clusterEntry(const host::nbv::ClusterVisit& visit) const {
  const FruitletCluster& cluster = world->clusters()[visit.index];
  nlohmann::json entry = {{"index", visit.index},
                          {"tag_id", cluster.tag.tag_id},
                          {"gt_fruitlets", cluster.fruitlet_indices.size()},
                          {"start_sim_s", visit.arrival_s}};
  if (visit.approach_distance_m) entry["approach_distance_m"] = *visit.approach_distance_m;
  if (visit.approach_yaw_deg) entry["approach_yaw_deg"] = *visit.approach_yaw_deg;
  return entry;
}

// One visited cluster into its entry and the tour's totals.
void Trial::Impl::recordCluster(const host::nbv::ClusterVisit& visit, TrialParts& cluster_parts,
                                const ClusterOutcome& outcome, const TrialLog& log,
                                nlohmann::json& entry, TourRecord& tour) {
  const std::size_t k = visit.index;
  entry["approaches_without_tag"] = visit.run->approaches_without_tag;
  if (*options.register_views)
    entry["anchor_offset"] =
        anchorOffsetJson(cluster_parts.session(), log.trueAnchorShift(), log.trueFrameError());
  entry["status"] = host::nbv::toString(visit.status);
  ++tour.cluster_status[entry["status"].get<std::string>()];
  entry["views"] = outcome.run.views;
  entry["first_view"] = log.firstView();  // the run's number of its first view
  entry["stop_reason"] = outcome.run.stop_reason;
  entry["sim_time_s"] = robot->clock().now_s() - visit.loop_start_s;

  for (auto& [key, value] : outcome.sizing.items()) {
    if (key.rfind("fruitlets", 0) == 0) {
      // Every scored fruitlet says which cluster it is in.
      nlohmann::json tagged = value;
      for (auto& f : tagged) f["cluster"] = k;
      for (const auto& f : tagged) tour.scored[key].push_back(f);
      entry[key] = std::move(tagged);
    } else if (key == "detections" || key.rfind("metrics", 0) == 0 || key == "sizing_estimator" ||
               key == "unsupported_detections" || key == "sized_fruitlets" ||
               key == "sizing_stats" || key == "T_world_tag") {
      entry[key] = value;
    }
  }
  tour.detections += outcome.sizing.value("detections", std::uint64_t{0});
  tour.views += outcome.run.views;
  entry["events"] = eventsJson(outcome.run.events);
  entry["events"].update(outcome.guidance_events);
  if (!outcome.memory.is_null()) entry["memory"] = outcome.memory;
  addNumbers(tour.events, entry["events"]);
  addNumbers(tour.wall, {{"perception", outcome.run.wall_s.perception},
                         {"mapping", outcome.run.wall_s.mapping},
                         {"tsdf", outcome.run.wall_s.tsdf},
                         {"planning", outcome.run.wall_s.planning},
                         {"goal_check", outcome.run.wall_s.goal_check},
                         {"motion_planning", outcome.run.wall_s.motion_planning},
                         {"sizing", outcome.sizing_wall_s},
                         {"sizing_during_loop", outcome.sizing_during_loop_s}});
  if (!outcome.size_history.is_null()) entry["size_history"] = outcome.size_history;
  for (const auto& T : outcome.run.camera_poses) tour.camera_path.push_back(T.translation());
  tour.planner_config = nlohmann::json::parse(cluster_parts.planner().configJson());
  tour.trial_config = cluster_parts.configJson(setup->options().sizing);
}

// Written as the tour goes (the map moves on); a failure is recorded with the tree's result,
// not the end of the tour.
void Trial::Impl::writeClusterOutputs(std::size_t k, const TrialParts& cluster_parts,
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
      for (const char* other :
           {"fruitlets_paper_sizing", "fruitlets_ours_sizing", "fruitlets_tag_frame"})
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
  result["settings"] = trialSettingsJson(options);
  result["planner"] = options.planner;
  result["seed"] = options.seed;
  result["engine"] = setup->engine();
  result["backend"] = backendName();
  result["views"] = tour.views;
  result["stop_reason"] = "tour_done";
  result["sim_time_s"] = robot->clock().now_s();
  result["budget_s"] = options.budget_s;
  result["wall_time_s"] = secondsSince(wall_start);
  result["status"] = tour.cluster_status["sized"] > 0 ? "ok" : "no_tag";
  result["config"] = {{"planner", tour.planner_config},
                      {"arm", nlohmann::json::parse(robot->armConfig().toJson())},
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
                    {"transit_motion_sim_s", tour.transit_motion_s},
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
  return impl_->robot->camera();
}

host::nbv::Arm& Trial::simulatedArm() {
  return impl_->robot->arm();
}

nlohmann::json Trial::run() {
  return impl_->run(simulatedCamera(), simulatedArm());
}

nlohmann::json Trial::run(host::nbv::Camera& camera, host::nbv::Arm& arm) {
  return impl_->run(camera, arm);
}

bool registerViewsOf(const TrialOptions& options) {
  if (options.register_views) return *options.register_views;
  const WorldConfig world = options.world_config.empty()
                                ? WorldConfig{}
                                : WorldConfig::fromYamlFile(options.world_config);
  return world.run_register_views != 0;
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
