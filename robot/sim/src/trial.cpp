#include "fvp/robot/sim/trial.h"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "fvp/accel/backend.h"
#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/planner/view_planner.h"
#include "fvp/host/session/mapping_session.h"
#include "fvp/robot/arm_controller.h"
#include "fvp/robot/arm_model.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/world.h"
#include "fvp/robot/sim_clock.h"
#include "fvp/robot/workspace_tree.h"
#include "trial_parts.h"

namespace fvp::robot::sim {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

nlohmann::json vec3(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

void validate(const TrialOptions& o) {
  if (o.planner != "fvp" && o.planner != "rvp")
    throw std::invalid_argument("trial option 'planner': expected fvp or rvp, got '" + o.planner +
                                "'");
  if (!(o.budget_s > 0.0) || !std::isfinite(o.budget_s))
    throw std::invalid_argument("trial option 'budget_s': expected a positive number of seconds");
  if (o.clock != "wall" && o.clock != "fixed")
    throw std::invalid_argument("trial option 'clock': expected wall or fixed, got '" + o.clock +
                                "'");
  if (!o.engine.empty() && o.engine != "grid" && o.engine != "octomap")
    throw std::invalid_argument("trial option 'engine': expected grid or octomap, got '" +
                                o.engine + "'");
  if (o.max_views && *o.max_views < 1)
    throw std::invalid_argument("trial option 'max_views': expected at least 1");
}

/// Counted expected events of one trial (never errors).
struct TrialEvents {
  std::size_t move_attempts = 0, failed_moves = 0, planning_iterations = 0, rejected_clearance = 0,
              iterations_without_move = 0, views_without_tag = 0, culled_rays = 0,
              collision_voxels_freed_at_arm = 0;
  std::int64_t dropped_disparities = 0, saturated_disparities = 0;
  std::map<std::string, std::size_t> motion_status;
};

}  // namespace

nlohmann::json runTrial(const TrialOptions& options) {
  validate(options);
  if (!options.out_dir.empty()) {
    host::prepareOutputDirectory(options.out_dir, "trial output directory");
    host::removeStaleOutputs(options.out_dir, TrialParts::outputFiles(), {"views"});
  }
  std::vector<std::string> warnings;
  const auto warn = [&](const std::string& text) {
    warnings.push_back(text);
    if (options.on_warning) options.on_warning(text);
  };
  const auto wall_start = Clock::now();
  const std::string engine =
      options.engine.empty() ? defaultEngine(options.planner) : options.engine;

  // Maps (and TSDF) fed view by view, the planner, and the sizing at the end. First: a
  // missing backend or a bad planner config fails before the world and the arm are built.
  std::unique_ptr<accel::Backend> backend;
  if (engine == "grid" || options.backend != "auto")
    backend = accel::createBackend(options.backend);
  TrialParts parts(options, engine, backend.get());

  // The world and the simulated camera.
  const WorldConfig world_config = options.world_config.empty()
                                       ? WorldConfig{}
                                       : WorldConfig::fromYamlFile(options.world_config);
  const World world = World::generate(world_config, options.seed);
  RenderConfig render_config;
  render_config.noise_seed = options.seed;
  const StereoRenderer renderer(world, render_config);

  // The arm, its workspace tree and the simulated clock.
  ArmConfig arm_config;
  arm_config.clock = options.clock;
  if (arm_config.workspace_cache_dir.empty()) arm_config.workspace_cache_dir = defaultCacheDir();
  const ArmModel arm(arm_config);
  std::ostringstream arm_log;
  const WorkspaceTree workspace = WorkspaceTree::loadOrBuild(arm, arm_log);
  std::istringstream arm_log_lines(arm_log.str());
  for (std::string line; std::getline(arm_log_lines, line);)
    if (line.rfind("warning: ", 0) == 0) warn(line.substr(9));
  SimClock clock = SimClock::fromConfig(arm_config);
  const auto start = ArmController::startConfiguration(arm, world.startCameraPose());
  if (!start)
    throw std::runtime_error("world seed " + std::to_string(options.seed) +
                             ": the start view is out of the arm's reach");
  ArmController controller(arm, clock, *start);

  TrialEvents events;
  nlohmann::json view_log = nlohmann::json::array();
  nlohmann::json plan_log = nlohmann::json::array();
  std::vector<Eigen::Vector3d> camera_path;
  double render_wall_s = 0.0, perceive_wall_s = 0.0, planning_wall_s = 0.0,
         motion_planning_wall_s = 0.0, mapping_wall_s = 0.0, tsdf_wall_s = 0.0;
  int views = 0;
  bool capture_next = true;
  std::size_t collision_map_scans = 0;  // the map's scan count when the arm last got it
  const auto budget_left = [&] { return clock.now_s() < options.budget_s; };
  const auto views_left = [&] { return !options.max_views || views < *options.max_views; };

  while (budget_left() && views_left()) {
    clock.beginIteration();
    if (capture_next) {
      const Eigen::Isometry3d T_world_camera = controller.cameraPose();
      // The trial perceives from the images alone: no ground-truth depth or ids to render.
      RenderOptions render_options;
      render_options.ground_truth = false;
      const host::StereoFrame frame = renderer.render(T_world_camera, render_options);
      render_wall_s += renderer.lastRenderSeconds();
      clock.chargeCapture();
      const ViewOutcome view = parts.addView(frame);
      perceive_wall_s += view.result.perceive_s;
      mapping_wall_s += view.mapping_s;
      tsdf_wall_s += view.tsdf_s;
      clock.chargeCompute(ClockStage::kMapping, view.mapping_s);
      clock.chargeCompute(ClockStage::kTsdf, view.tsdf_s);
      clock.recordUncharged(renderer.lastRenderSeconds(), view.result.perception.sgbm_s);
      events.dropped_disparities += view.result.perception.droppedDisparities();
      events.saturated_disparities += view.result.perception.saturated;
      if (!view.result.tag_detected) ++events.views_without_tag;
      camera_path.push_back(T_world_camera.translation());
      view_log.push_back({{"index", views},
                          {"position_m", vec3(T_world_camera.translation())},
                          {"tag_detected", view.result.tag_detected},
                          {"roi_points", view.result.roi_points},
                          {"other_points", view.result.other_points},
                          {"render_s", renderer.lastRenderSeconds()},
                          {"perceive_s", view.result.perceive_s},
                          {"mapping_s", view.mapping_s},
                          {"tsdf_s", view.tsdf_s},
                          {"sim_time_s", clock.now_s()}});
      if (!options.out_dir.empty()) parts.keepViewImage(views, frame);
      ++views;
      if (options.on_progress)
        options.on_progress({views, clock.now_s(), options.budget_s, secondsSince(wall_start)});
      if (!budget_left() || !views_left()) break;
    }
    host::map::MapEngine* map = parts.map();
    if (!map) {
      // No Cluster Region yet: the tag was not seen from the start view. Nothing to plan on;
      // an expected outcome of a heavily occluded tag, reported, never a crash.
      break;
    }

    // The arm's collision map follows the coarse map after new scans only (planning again
    // after a failed move keeps it); building it is map upkeep, charged as mapping. The
    // voxels the arm occupies where it stands are freed in it (counted per rebuild, so a
    // voxel seen again after the next scan counts again).
    if (collision_map_scans != map->scanCount()) {
      const auto t_collision = Clock::now();
      events.collision_voxels_freed_at_arm += controller.setMap(map->coarseOcTree());
      collision_map_scans = map->scanCount();
      const double collision_s = secondsSince(t_collision);
      mapping_wall_s += collision_s;
      clock.chargeCompute(ClockStage::kMapping, collision_s);
    }
    // Plan and move. Planning is charged as its wall time minus the moves it made (the
    // controller charges motion planning and motion itself).
    double move_wall_s = 0.0;
    const host::planner::ReachabilityFn reachable = [&](const Eigen::Isometry3d& T) {
      return workspace.reachable(T);
    };
    const host::planner::MoveToPoseFn move = [&](const Eigen::Isometry3d& T) {
      const auto t0 = Clock::now();
      const MotionPlan plan = controller.moveToPose(T);
      move_wall_s += secondsSince(t0);
      motion_planning_wall_s += plan.planning_wall_s;
      ++events.motion_status[toString(plan.status)];
      return plan.ok();
    };
    const auto t_plan = Clock::now();
    const host::planner::PlanStep step =
        parts.planner().planAndMove(*map, controller.cameraPose(), reachable, move);
    const double plan_s = std::max(0.0, secondsSince(t_plan) - move_wall_s);
    planning_wall_s += plan_s;
    clock.chargeCompute(ClockStage::kPlanning, plan_s);
    ++events.planning_iterations;
    events.move_attempts += step.move_attempts;
    events.failed_moves += step.failed_moves;
    events.rejected_clearance += step.rejected_clearance;
    events.culled_rays += step.culled_rays;
    nlohmann::json timings = nlohmann::json::object();
    for (const auto& [stage, s] : step.timings_s) timings[stage] = s;
    plan_log.push_back(
        {{"candidates", step.candidates.size()},
         {"moved", step.moved()},
         {"move_attempts", step.move_attempts},
         {"failed_moves", step.failed_moves},
         {"sampling_rounds", step.sampling_rounds},
         {"chosen_utility",
          step.chosen ? nlohmann::json(step.candidates[*step.chosen].utility) : nlohmann::json()},
         {"planning_s", plan_s},
         {"timings_s", timings}});
    // Without a move, a new capture would see the same view: plan again (the planner's
    // threshold has decayed) until a move succeeds or the budget is spent.
    capture_next = step.moved();
    if (!step.moved()) ++events.iterations_without_move;
  }

  // Size, score and write.
  const auto t_size = Clock::now();
  nlohmann::json sizing = parts.sizeAndScore(world, options.out_dir);
  const double sizing_wall_s = secondsSince(t_size);

  nlohmann::json result;
  result["planner"] = options.planner;
  result["seed"] = options.seed;
  result["engine"] = engine;
  result["backend"] = backend ? std::string(accel::toString(backend->kind())) : "none";
  result["views"] = views;
  result["sim_time_s"] = clock.now_s();
  result["budget_s"] = options.budget_s;
  result["wall_time_s"] = secondsSince(wall_start);
  result["status"] = parts.map() ? "ok" : "no_tag";
  result["config"] = {{"planner", nlohmann::json::parse(parts.planner().configJson())},
                      {"arm", nlohmann::json::parse(arm_config.toJson())},
                      {"trial", parts.configJson()}};
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
                            {"collision_voxels_freed_at_arm", events.collision_voxels_freed_at_arm},
                            {"motion_status", events.motion_status}};
  result["events"] = counted;
  result["wall_breakdown_s"] = {
      {"rendering", render_wall_s},  {"perception", perceive_wall_s},
      {"mapping", mapping_wall_s},   {"tsdf", tsdf_wall_s},
      {"planning", planning_wall_s}, {"motion_planning", motion_planning_wall_s},
      {"sizing", sizing_wall_s}};
  result["clock"] = nlohmann::json::parse(clock.toJson());
  result["view_log"] = view_log;
  result["plan_log"] = plan_log;
  nlohmann::json path = nlohmann::json::array();
  for (const auto& p : camera_path) path.push_back(vec3(p));
  result["camera_path_m"] = path;

  result["warnings"] = warnings;
  if (!options.out_dir.empty())
    parts.writeOutputs(result, world, camera_path, options.out_dir, warn);
  return result;
}

}  // namespace fvp::robot::sim

namespace fvp::robot::sim {

std::string trialSummary(const nlohmann::json& result) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1);
  s << "planner " << result.value("planner", "?") << ", world seed " << result.value("seed", 0)
    << ", engine " << result.value("engine", "?") << ", backend " << result.value("backend", "?")
    << "\n"
    << "views " << result.value("views", 0) << ", simulated " << result.value("sim_time_s", 0.0)
    << " s of " << result.value("budget_s", 0.0) << " s, wall " << result.value("wall_time_s", 0.0)
    << " s\n";
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

}  // namespace fvp::robot::sim
