// The simulator as a robot (docs/design.md section 8): a world from a seed, its stereo camera
// (with the world's pose, wind and segmentation errors), the UR5 on its slider with its
// workspace tree, and the simulated clock they charge. It supplies what a robot would to the
// library's NbvSetup (camera, arm, clock, the clusters to visit) and the ground truth a trial
// scores against; it plans and sizes nothing itself.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fvp/host/nbv/arm.h"
#include "fvp/host/nbv/camera.h"
#include "fvp/host/nbv/loop_clock.h"
#include "fvp/host/nbv/nbv_setup.h"
#include "fvp/robot/arm_config.h"
#include "fvp/robot/sim/sim_clock.h"
#include "fvp/robot/workspace_tree.h"

namespace fvp::robot::sim {
class World;
class SimulatedArm;
class SimulatedCamera;
}  // namespace fvp::robot::sim

namespace fvp::trials {

struct SimulatedRobotOptions {
  std::uint64_t seed = 1;              ///< the world, its noise and its errors
  std::filesystem::path world_config;  ///< empty: robot/sim/config/world_default.yaml's values
  /// The season's day to visit (docs/simulation.md "A season"): overrides the world config's
  /// season_day. The world is the seed's, grown; what a visit draws anew (noise, wind, light,
  /// pose and segmentation errors, motion planning) comes from robot::sim::visitSeed.
  std::optional<double> season_day;
  std::filesystem::path arm_config;  ///< empty: the built-in arm
  /// "wall": compute charged as measured; "fixed": as constants, and motion planning
  /// reproducible (the same run on any machine).
  robot::sim::SimClock::Mode clock = robot::sim::SimClock::Mode::kWall;
  /// Perception's charge on the fixed clock: that of the setup's stereo pass
  /// (robot::sim::fixedPerceptionTimeS(NbvSetupOptions::guided_stereo)).
  double fixed_perception_time_s = robot::sim::kDefaultFixedPerceptionTimeS;
  /// Each warning (a rebuilt workspace cache), as it happens.
  std::function<void(const std::string&)> on_warning;
};

class SimulatedRobot {
 public:
  /// Throws std::invalid_argument / std::runtime_error for bad options or files, and when the
  /// world's start view is out of the arm's reach.
  explicit SimulatedRobot(const SimulatedRobotOptions& options);
  ~SimulatedRobot();
  SimulatedRobot(const SimulatedRobot&) = delete;
  SimulatedRobot& operator=(const SimulatedRobot&) = delete;

  /// The renderer at the given pose, each capture charged to the simulated clock.
  robot::sim::SimulatedCamera& camera();
  const robot::sim::SimulatedCamera& camera() const;
  /// The UR5 on its slider: workspace-tree reachability, IK + OMPL, charged moves.
  host::nbv::Arm& arm();
  /// The same arm, with what a driver does besides the loop's moves (the ROS bridge).
  robot::sim::SimulatedArm& simulatedArm();
  /// The simulated clock as the loop's clock.
  host::nbv::LoopClock& loopClock();
  const robot::sim::SimClock& clock() const;
  const robot::sim::World& world() const;
  const robot::ArmConfig& armConfig() const;
  /// The world's clusters as the library's targets: in a world of several clusters only a
  /// cluster's own tag places its region (one cluster: the perception config's tag).
  const std::vector<host::nbv::ClusterTarget>& clusterTargets() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Where the workspace tree is cached between runs (robot/workspace_tree.h).
using robot::defaultCacheDir;

}  // namespace fvp::trials
