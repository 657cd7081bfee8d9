#include "fvp/trials/trial.h"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "fvp/accel/backend.h"
#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/eval/fruitlet_matching.h"
#include "fvp/host/map/map_engine_registry.h"
#include "fvp/host/nbv/cluster_completion.h"
#include "fvp/host/nbv/loop_observers.h"
#include "fvp/host/nbv/nbv_loop.h"
#include "fvp/host/planner/planner_registry.h"
#include "fvp/host/planner/view_planner.h"
#include "fvp/host/session/mapping_session.h"
#include "fvp/robot/arm_model.h"
#include "fvp/robot/sim/arm_controller.h"
#include "fvp/robot/sim/simulated_arm.h"
#include "fvp/robot/sim/simulated_camera.h"
#include "fvp/robot/sim/simulated_loop_clock.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/world.h"
#include "fvp/robot/workspace_tree.h"
#include "trial_parts.h"

namespace fvp::trials {
// The simulator's parts and the arm, by their short names.
using namespace fvp::robot;
using namespace fvp::robot::sim;
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

nlohmann::json vec3(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
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
  TrialLog(const TrialParts& parts, const SimulatedCamera& camera, const TrialOptions& options,
           Clock::time_point wall_start)
      : parts_(parts), camera_(camera), options_(options), wall_start_(wall_start) {}

  void onView(const host::nbv::ViewEvent& e) override {
    const host::ViewResult& v = *e.result;
    views_.push_back({{"index", e.index},
                      {"position_m", vec3(e.T_world_camera.translation())},
                      {"tag_detected", v.tag_detected},
                      {"roi_points", v.roi_points},
                      {"other_points", v.other_points},
                      {"render_s", camera_.lastRenderSeconds()},
                      {"perceive_s", v.perceive_s},
                      {"mapping_s", v.scan.seconds},
                      {"tsdf_s", v.tsdf_s},
                      {"sim_time_s", e.now_s}});
    if (!options_.out_dir.empty()) parts_.keepViewImage(e.index, *e.frame);
    if (options_.on_progress)
      options_.on_progress({e.index + 1, e.now_s, options_.budget_s, secondsSince(wall_start_)});
  }

  void onPlan(const host::nbv::PlanEvent& e) override {
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
         {"planning_s", e.planning_s},
         {"timings_s", timings}});
  }

  const nlohmann::json& views() const { return views_; }
  const nlohmann::json& plans() const { return plans_; }

 private:
  const TrialParts& parts_;
  const SimulatedCamera& camera_;
  const TrialOptions& options_;
  Clock::time_point wall_start_;
  nlohmann::json views_ = nlohmann::json::array(), plans_ = nlohmann::json::array();
};

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
nlohmann::json sizeHistoryJson(const std::vector<host::nbv::SizingSnapshot>& history,
                               const World& world) {
  std::vector<Eigen::Vector3d> truth_m;
  std::vector<double> truth_mm;
  for (const auto& f : world.fruitlets()) {
    truth_m.push_back(f.center_m);
    truth_mm.push_back(f.gtSizeMm());
  }
  nlohmann::json out = nlohmann::json::array();
  for (const auto& snapshot : history) {
    std::vector<Eigen::Vector3d> centres;
    std::vector<double> sizes;
    nlohmann::json fruitlets = nlohmann::json::array();
    for (const auto& f : snapshot.fruitlets) {
      centres.push_back(f.center_m);
      sizes.push_back(f.size_mm);
      fruitlets.push_back({{"center_m", vec3(f.center_m)},
                           {"size_mm", f.size_mm},
                           {"well_seen_images", f.well_seen_images},
                           {"view_span_deg", f.view_span_deg},
                           {"size_source", host::sizing::toString(f.size_source)}});
    }
    const auto m = host::eval::sizeMetrics(
        truth_mm, sizes, host::eval::matchFruitlets(centres, truth_m), centres.size());
    const auto opt = [](const std::optional<double>& v) {
      return v ? nlohmann::json(*v) : nlohmann::json();
    };
    out.push_back({{"view", snapshot.view},
                   {"sim_time_s", snapshot.now_s},
                   {"sizing_wall_s", snapshot.sizing_s},
                   {"fruitlets", fruitlets},
                   {"match_percent", m.match_percent},
                   {"mae_mm", opt(m.mae_mm)},
                   {"precision_percent", opt(m.precision_percent)}});
  }
  return out;
}

}  // namespace

struct Trial::Impl {
  explicit Impl(TrialOptions opts) : options(std::move(opts)) {
    validate(options);
    if (!options.out_dir.empty()) {
      host::prepareOutputDirectory(options.out_dir, "trial output directory");
      host::removeStaleOutputs(options.out_dir, TrialParts::outputFiles(), {"views"});
    }
    engine = options.engine.empty() ? defaultEngine(options.planner) : options.engine;

    // Maps (and TSDF) fed view by view, the planner, and the sizing at the end. First: a
    // missing backend or a bad planner config fails before the world and the arm are built.
    backend = host::map::createBackendFor(engine, options.backend);
    parts = std::make_unique<TrialParts>(options, engine, backend.get());

    // The world and the simulated camera.
    const WorldConfig world_config = options.world_config.empty()
                                         ? WorldConfig{}
                                         : WorldConfig::fromYamlFile(options.world_config);
    world = std::make_unique<World>(World::generate(world_config, options.seed));
    RenderConfig render_config;
    render_config.noise_seed = options.seed;
    renderer = std::make_unique<StereoRenderer>(*world, render_config);

    // The arm, its workspace tree and the simulated clock.
    if (arm_config.workspace_cache_dir.empty()) arm_config.workspace_cache_dir = defaultCacheDir();
    arm = std::make_unique<ArmModel>(arm_config);
    workspace = std::make_unique<WorkspaceTree>(
        loadWorkspaceTree(*arm, [this](const std::string& text) { warn(text); }));
    clock = std::make_unique<SimClock>(SimClock::modeFromString(options.clock));
    const auto start = ArmController::startConfiguration(*arm, world->startCameraPose());
    if (!start)
      throw std::runtime_error("world seed " + std::to_string(options.seed) +
                               ": the start view is out of the arm's reach");
    controller = std::make_unique<ArmController>(*arm, *clock, *start);
    // A fixed clock is for runs that repeat: then the moves must repeat too.
    if (clock->mode() == SimClock::Mode::kFixed)
      controller->setReproducibleMotionPlanning(options.seed);
    camera = std::make_unique<SimulatedCamera>(*renderer, *clock);
    sim_arm = std::make_unique<SimulatedArm>(*controller, *workspace);
  }

  void warn(const std::string& text) {
    warnings.push_back(text);
    if (options.on_warning) options.on_warning(text);
  }

  nlohmann::json run(host::nbv::Camera& loop_camera, host::nbv::Arm& loop_arm);

  TrialOptions options;
  Clock::time_point wall_start = Clock::now();
  std::vector<std::string> warnings;
  std::string engine;
  std::unique_ptr<accel::Backend> backend;
  std::unique_ptr<TrialParts> parts;
  std::unique_ptr<World> world;
  std::unique_ptr<StereoRenderer> renderer;
  ArmConfig arm_config;
  std::unique_ptr<ArmModel> arm;
  std::unique_ptr<WorkspaceTree> workspace;
  std::unique_ptr<SimClock> clock;
  std::unique_ptr<ArmController> controller;
  std::unique_ptr<SimulatedCamera> camera;
  std::unique_ptr<SimulatedArm> sim_arm;
  bool ran = false;
};

nlohmann::json Trial::Impl::run(host::nbv::Camera& loop_camera, host::nbv::Arm& loop_arm) {
  if (ran) throw std::logic_error("Trial::run: a trial runs once (its world and clock are spent)");
  ran = true;
  // The loop, driven through the camera, arm and clock like a robot's.
  SimulatedLoopClock loop_clock(*clock);
  host::nbv::StopCondition stop = host::nbv::StopCondition::budget(options.budget_s);
  if (options.max_views) stop = stop || host::nbv::StopCondition::views(*options.max_views);
  TrialLog log(*parts, *camera, options, wall_start);
  host::nbv::LoopObservers observers;
  observers.add(&log);
  UnchargedClock observing_clock(loop_clock);  // before completion: it outlives it
  std::optional<host::nbv::ClusterCompletion> completion;
  if (options.stop == "auto") {
    completion.emplace(parts->session(), loop_clock, parts->sizingConfig());
    observers.add(&*completion);
    stop = stop || completion->stopCondition();
  } else if (options.record_size_history) {
    completion.emplace(parts->session(), observing_clock, parts->sizingConfig());
    observers.add(&*completion);
  }
  host::nbv::NbvLoop loop(parts->session(), parts->planner(), loop_camera, loop_arm, loop_clock);
  const host::nbv::NbvResult run = loop.run(stop, &observers);
  const host::nbv::NbvEvents& events = run.events;
  std::vector<Eigen::Vector3d> camera_path;
  for (const auto& T : run.camera_poses) camera_path.push_back(T.translation());

  // Size, score and write.
  const auto t_size = Clock::now();
  nlohmann::json sizing = parts->sizeAndScore(*world, options.out_dir);
  const double sizing_wall_s = secondsSince(t_size);

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
  for (auto& [key, value] : sizing.items()) result[key] = value;
  nlohmann::json counted = {{"planning_iterations", events.planning_iterations},
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
  result["events"] = counted;
  double loop_sizing_s = 0.0;
  if (completion)
    for (const auto& snapshot : completion->history()) loop_sizing_s += snapshot.sizing_s;
  result["wall_breakdown_s"] = {{"rendering", camera->totalRenderSeconds()},
                                {"perception", run.wall_s.perception},
                                {"mapping", run.wall_s.mapping},
                                {"tsdf", run.wall_s.tsdf},
                                {"planning", run.wall_s.planning},
                                {"motion_planning", run.wall_s.motion_planning},
                                {"sizing", sizing_wall_s},
                                {"sizing_during_loop", loop_sizing_s}};
  if (completion) result["size_history"] = sizeHistoryJson(completion->history(), *world);
  if (options.stop == "auto") {
    result["stop"] = {{"rule", "auto"},
                      {"stable_views", completion->config().stable_views},
                      {"size_tolerance_mm", completion->config().size_tolerance_mm},
                      {"same_fruitlet_m", completion->config().same_fruitlet_m},
                      {"min_well_seen_images", completion->config().min_well_seen_images},
                      {"min_view_span_deg", completion->config().min_view_span_deg}};
  } else {
    result["stop"] = {{"rule", "budget"}};
  }
  result["clock"] = nlohmann::json::parse(clock->toJson());
  result["view_log"] = log.views();
  result["plan_log"] = log.plans();
  nlohmann::json path = nlohmann::json::array();
  for (const auto& p : camera_path) path.push_back(vec3(p));
  result["camera_path_m"] = path;

  result["warnings"] = warnings;
  if (!options.out_dir.empty())
    parts->writeOutputs(result, *world, camera_path, options.out_dir, options.on_warning);
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
