#include "fvp/trials/simulated_robot.h"

#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "fvp/robot/arm_model.h"
#include "fvp/robot/sim/pose_error_model.h"
#include "fvp/robot/sim/season_growth.h"
#include "fvp/robot/sim/segmentation_model.h"
#include "fvp/robot/sim/sim_clock.h"
#include "fvp/robot/sim/simulated_arm.h"
#include "fvp/robot/sim/simulated_camera.h"
#include "fvp/robot/sim/simulated_loop_clock.h"
#include "fvp/robot/sim/stereo_renderer.h"
#include "fvp/robot/sim/wind_model.h"
#include "fvp/robot/sim/world.h"
#include "fvp/robot/workspace_tree.h"
#include "trial_parts.h"

namespace fvp::trials {
using namespace fvp::robot;
using namespace fvp::robot::sim;

namespace {

std::vector<host::nbv::ClusterTarget> targetsOf(const World& world) {
  std::vector<host::nbv::ClusterTarget> targets;
  for (const FruitletCluster& c : world.clusters()) {
    host::nbv::ClusterTarget t;
    if (world.clusters().size() > 1) t.tag_id = c.tag.tag_id;
    t.T_world_start_camera = c.T_world_start_camera;
    t.center_m = c.center_m;
    targets.push_back(t);
  }
  return targets;
}

WorldConfig worldConfigOf(const SimulatedRobotOptions& o) {
  WorldConfig config =
      o.world_config.empty() ? WorldConfig{} : WorldConfig::fromYamlFile(o.world_config);
  if (o.season_day) {
    config.season_day = *o.season_day;
    config.validate("the visit's season_day (--season-day)");
  }
  return config;
}

}  // namespace

struct SimulatedRobot::Impl {
  explicit Impl(const SimulatedRobotOptions& o)
      : world(World::generate(worldConfigOf(o), o.seed)),
        visit_seed(visitSeed(o.seed, world.config().season_day)),
        targets(targetsOf(world)) {
    RenderConfig render_config = renderConfigFor(world.config(), {}, visit_seed);
    render_config.noise_seed = visit_seed;
    renderer = std::make_unique<StereoRenderer>(world, render_config);
    if (!o.arm_config.empty()) arm_config = ArmConfig::fromYamlFile(o.arm_config);
    if (arm_config.workspace_cache_dir.empty()) arm_config.workspace_cache_dir = defaultCacheDir();
    arm = std::make_unique<ArmModel>(arm_config);
    workspace =
        std::make_unique<WorkspaceTree>(loadWorkspaceTree(*arm, [&o](const std::string& text) {
          if (o.on_warning) o.on_warning(text);
        }));
    clock = std::make_unique<SimClock>(o.clock, kDefaultCaptureTimeS, kDefaultFixedStageTimeS,
                                       o.fixed_perception_time_s);
    loop_clock = std::make_unique<SimulatedLoopClock>(*clock);
    const auto start = SimulatedArm::startConfiguration(*arm, world.startCameraPose());
    if (!start)
      throw std::runtime_error("world seed " + std::to_string(o.seed) +
                               ": the start view is out of the arm's reach");
    sim_arm = std::make_unique<SimulatedArm>(*arm, *workspace, *clock, *start);
    // A fixed clock is for runs that repeat: then the moves must repeat too.
    if (clock->mode() == SimClock::Mode::kFixed) sim_arm->setReproducibleMotionPlanning(visit_seed);
    pose_errors = std::make_unique<PoseErrorModel>(world.config(), visit_seed);
    wind = std::make_unique<WindModel>(world, visit_seed);
    segmentation = std::make_unique<SegmentationModel>(world.config(), visit_seed);
    camera = std::make_unique<SimulatedCamera>(
        *renderer, *clock,
        SimulatedErrors{pose_errors->enabled() ? pose_errors.get() : nullptr,
                        wind->enabled() ? wind.get() : nullptr,
                        segmentation->enabled() ? segmentation.get() : nullptr});
  }

  World world;
  std::uint64_t visit_seed;
  std::vector<host::nbv::ClusterTarget> targets;
  std::unique_ptr<StereoRenderer> renderer;
  ArmConfig arm_config;
  std::unique_ptr<ArmModel> arm;
  std::unique_ptr<WorkspaceTree> workspace;
  std::unique_ptr<SimClock> clock;
  std::unique_ptr<SimulatedLoopClock> loop_clock;
  std::unique_ptr<PoseErrorModel> pose_errors;
  std::unique_ptr<WindModel> wind;
  std::unique_ptr<SegmentationModel> segmentation;
  std::unique_ptr<SimulatedCamera> camera;
  std::unique_ptr<SimulatedArm> sim_arm;
};

SimulatedRobot::SimulatedRobot(const SimulatedRobotOptions& options)
    : impl_(std::make_unique<Impl>(options)) {}
SimulatedRobot::~SimulatedRobot() = default;

SimulatedCamera& SimulatedRobot::camera() {
  return *impl_->camera;
}
const SimulatedCamera& SimulatedRobot::camera() const {
  return *impl_->camera;
}
host::nbv::Arm& SimulatedRobot::arm() {
  return *impl_->sim_arm;
}
SimulatedArm& SimulatedRobot::simulatedArm() {
  return *impl_->sim_arm;
}
host::nbv::LoopClock& SimulatedRobot::loopClock() {
  return *impl_->loop_clock;
}
const SimClock& SimulatedRobot::clock() const {
  return *impl_->clock;
}
const World& SimulatedRobot::world() const {
  return impl_->world;
}
const ArmConfig& SimulatedRobot::armConfig() const {
  return impl_->arm_config;
}
const std::vector<host::nbv::ClusterTarget>& SimulatedRobot::clusterTargets() const {
  return impl_->targets;
}

}  // namespace fvp::trials
