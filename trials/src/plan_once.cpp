#include "fvp/trials/plan_once.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "fvp/accel/backend.h"
#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/map/map_engine_registry.h"
#include "fvp/host/perception/capture.h"
#include "fvp/host/perception/ply_io.h"
#include "fvp/host/planner/planner_registry.h"
#include "fvp/host/session/capture_sizing.h"
#include "fvp/host/session/mapping_session.h"
#include "fvp/robot/sim/arm_controller.h"
#include "fvp/robot/sim/camera_views.h"
#include "fvp/robot/sim/simulated_mapping.h"
#include "fvp/robot/workspace_tree.h"
#include "fvp/trials/simulated_robot.h"
#include "trial_parts.h"

namespace fvp::trials {
// The simulator's parts and the arm, by their short names.
using namespace fvp::robot;
using namespace fvp::robot::sim;
namespace {

nlohmann::json vec3(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

/// Blue (low) -> red (high) over the utilities of the reachable candidates; grey for the
/// unreachable.
std::array<std::uint8_t, 3> colour(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return {std::uint8_t(255 * t), std::uint8_t(255 * (1 - std::abs(2 * t - 1))),
          std::uint8_t(255 * (1 - t))};
}

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

/// One planning iteration and what it took: mapping, then planning with its moves.
struct PlanRun {
  host::planner::PlanStep step;
  double map_s = 0.0, plan_s = 0.0;
  nlohmann::json motions = nlohmann::json::array();
  nlohmann::json warnings = nlohmann::json::array();
};

// A robot's captures: the map from every view (their own masks and disparities as given),
// the camera where the last view was taken. The robot's own planner makes the move, so every
// candidate counts as reachable and the best one is chosen.
PlanRun planFromCaptures(const PlanOnceOptions& o, const std::vector<std::filesystem::path>& dirs,
                         const host::PerceptionConfig& perception, host::nbv::ClusterWork& work) {
  PlanRun run;
  const auto t_map = std::chrono::steady_clock::now();
  host::MappingSession& session = *work.session;
  host::planner::ViewPlanner& planner = *work.planner;
  Eigen::Isometry3d T_now = Eigen::Isometry3d::Identity();
  for (const auto& dir : dirs) {
    const host::Capture capture = host::readCapture(dir);
    session.addView(host::toStereoFrame(capture));
    T_now = capture.T_world_camera;
  }
  run.map_s = secondsSince(t_map);
  if (!session.map())
    throw std::runtime_error("plan: no capture in " + o.captures_dir.string() +
                             " showed the AprilTag (" + perception.tag.family + " id " +
                             std::to_string(perception.tag.tag_id) +
                             ") and no region_center_m is configured: no Cluster Region, "
                             "no map");
  const auto t_plan = std::chrono::steady_clock::now();
  run.step = host::planner::planAndMove(
      planner, *session.map(), T_now, [](const Eigen::Isometry3d&) { return true; },
      [&](const Eigen::Isometry3d&) {
        run.motions.push_back({{"status", "not_planned"}});
        return true;
      });
  run.plan_s = secondsSince(t_plan);
  return run;
}

// A simulated world mapped from o.views views on an arc, then planned from its start view
// with the simulated arm making the moves.
PlanRun planInSimulation(const PlanOnceOptions& o, const std::string& engine,
                         const host::map::MapConfig& map_config, accel::Backend* backend,
                         host::planner::ViewPlanner& planner) {
  PlanRun run;
  const auto t_map = std::chrono::steady_clock::now();
  const WorldConfig world_config =
      o.world_config.empty() ? WorldConfig{} : WorldConfig::fromYamlFile(o.world_config);
  const World world = World::generate(world_config, o.seed);
  SimulatedMappingOptions mapping;
  mapping.engine = engine;
  mapping.map = map_config;
  mapping.render.noise_seed = o.seed;
  SimulatedMapping mapped =
      mapSimulatedViews(world, orbitViews(world, o.views, 90.0), mapping, backend);
  run.map_s = secondsSince(t_map);
  if (!mapped.map)
    throw std::runtime_error("plan: no view detected the AprilTag: no Cluster Region, no map");

  ArmConfig arm_config;
  arm_config.workspace_cache_dir = defaultCacheDir();
  const ArmModel arm(arm_config);
  const WorkspaceTree workspace =
      loadWorkspaceTree(arm, [&](const std::string& text) { run.warnings.push_back(text); });
  SimClock clock(SimClock::Mode::kWall);
  const auto start = ArmController::startConfiguration(arm, world.startCameraPose());
  if (!start) throw std::runtime_error("plan: the start view is out of the arm's reach");
  ArmController controller(arm, clock, *start);
  controller.setMap(mapped.map->coarseOcTree());
  const auto t_plan = std::chrono::steady_clock::now();
  run.step = host::planner::planAndMove(
      planner, *mapped.map, controller.cameraPose(),
      [&](const Eigen::Isometry3d& T) { return workspace.reachable(T); },
      [&](const Eigen::Isometry3d& T) {
        const MotionPlan plan = controller.moveToPose(T);
        run.motions.push_back({{"status", toString(plan.status)},
                               {"planning_s", plan.planning_wall_s},
                               {"duration_s", plan.ok() ? plan.trajectory.duration_s() : 0.0}});
        return plan.ok();
      });
  run.plan_s = secondsSince(t_plan);
  return run;
}

/// plan.json's candidates, and their positions and colours for candidates.ply.
nlohmann::json candidatesJson(const host::planner::PlanStep& step,
                              std::vector<Eigen::Vector3f>& positions,
                              std::vector<std::array<std::uint8_t, 3>>& colours) {
  nlohmann::json candidates = nlohmann::json::array();
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& c : step.candidates)
    if (std::isfinite(c.utility)) lo = std::min(lo, c.utility), hi = std::max(hi, c.utility);
  for (const auto& c : step.candidates) {
    candidates.push_back(
        {{"kind", host::planner::toString(c.kind)},
         {"position_m", vec3(c.position_m())},
         {"target_m", vec3(c.target_m)},
         {"ig", c.ig},
         {"utility", std::isfinite(c.utility) ? nlohmann::json(c.utility) : nlohmann::json()},
         {"reachable", c.reachable}});
    positions.push_back(c.position_m().cast<float>());
    colours.push_back(std::isfinite(c.utility)
                          ? colour(hi > lo ? (c.utility - lo) / (hi - lo) : 1.0)
                          : std::array<std::uint8_t, 3>{128, 128, 128});
  }
  return candidates;
}

}  // namespace

nlohmann::json planOnce(const PlanOnceOptions& o) {
  if (!host::planner::PlannerRegistry::instance().contains(o.planner))
    throw std::invalid_argument("plan: --planner: expected one of " +
                                host::planner::PlannerRegistry::instance().knownNames() +
                                ", got '" + o.planner + "'");
  if (o.views < 1) throw std::invalid_argument("plan: --views: expected at least 1");
  std::optional<host::OutputDirectoryLock> lock;  // one writer, for the whole command
  if (!o.out_dir.empty()) {
    host::prepareOutputDirectory(o.out_dir, "plan output directory");
    lock.emplace(o.out_dir, "plan output directory");
    host::checkOutputPaths(o.out_dir, "plan output directory", {"plan.json", "candidates.ply"}, {});
    host::removeStaleOutputs(o.out_dir, {"plan.json", "candidates.ply"});
  }
  const std::string engine =
      o.engine.empty() ? host::planner::PlannerRegistry::instance().at(o.planner).default_engine
                       : o.engine;
  const bool from_captures = !o.captures_dir.empty();
  // Checked first: a bad config fails before anything is mapped.
  const host::PerceptionConfig perception =
      o.perception_config.empty() ? host::PerceptionConfig{}
                                  : host::PerceptionConfig::fromYamlFile(o.perception_config);
  std::vector<std::filesystem::path> capture_dirs;
  if (from_captures) capture_dirs = host::listCaptures(o.captures_dir);

  // The library's setup: the backend, the planner (seeded as a trial's) and, from captures,
  // the session the views are mapped into.
  host::nbv::NbvSetupOptions setup_options;
  setup_options.planner = o.planner;
  setup_options.planner_config = o.planner_config;
  setup_options.engine = engine;
  setup_options.backend = o.backend;
  setup_options.planner_seed = o.seed;
  setup_options.perception = perception;
  host::nbv::NbvSetup setup(setup_options);
  accel::Backend* backend = setup.backend();
  const std::unique_ptr<host::nbv::ClusterWork> work = setup.makeWork({});
  const host::map::MapConfig& map_config = work->map_config;
  const PlanRun run = from_captures
                          ? planFromCaptures(o, capture_dirs, perception, *work)
                          : planInSimulation(o, engine, map_config, backend, *work->planner);
  const host::planner::PlanStep& step = run.step;

  std::vector<Eigen::Vector3f> positions;
  std::vector<std::array<std::uint8_t, 3>> colours;
  const nlohmann::json candidates = candidatesJson(step, positions, colours);
  nlohmann::json timings = {{"mapping_views", run.map_s}, {"plan_and_move", run.plan_s}};
  for (const auto& [stage, s] : step.timings_s) timings[stage] = s;
  nlohmann::json result = {
      {"chosen", step.chosen ? nlohmann::json(*step.chosen) : nlohmann::json()},
      {"candidates", candidates},
      {"timings_s", timings},
      {"config", nlohmann::json::parse(work->planner->configJson())},
      {"planner", o.planner},
      {"seed", o.seed},
      {"views", from_captures ? int(capture_dirs.size()) : o.views},
      {"source", from_captures ? o.captures_dir.string() : std::string("simulated")},
      {"engine", engine},
      {"fine_map_extent", host::map::toString(map_config.fine_map_extent)},
      {"backend", backend ? std::string(accel::toString(backend->kind())) : "none"},
      {"move_attempts", step.move_attempts},
      {"failed_moves", step.failed_moves},
      {"rejected_clearance", step.rejected_clearance},
      {"gain_rays", step.gain_rays},
      {"culled_rays", step.culled_rays},
      {"motions", run.motions},
      {"warnings", run.warnings}};
  if (!o.out_dir.empty()) {
    // The result first, then the extra.
    host::writeFileAtomically(o.out_dir / "plan.json", "plan", result.dump(2) + "\n");
    host::writePlyColoredPoints(o.out_dir / "candidates.ply", positions, colours,
                                "fvp candidate camera positions, colour = utility (blue low, red "
                                "high, grey unscored)");
  }
  return result;
}

}  // namespace fvp::trials
