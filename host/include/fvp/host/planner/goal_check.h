// The arm's answer to "is there anywhere to go for this camera pose?", asked before a move is
// tried (docs/nbv-loop.md, "Goal checks"): inverse kinematics within the joint limits and one
// solution free of collision against the current map, without planning a motion. A pose that
// fails it cannot be moved to, so the loop does not try; an expected outcome, never an error.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <functional>
#include <limits>
#include <vector>

#include "fvp/host/planner/view_overhead.h"

namespace fvp::host::planner {

enum class GoalCheck {
  kFeasible,           ///< a collision-free IK solution exists (the motion may still fail)
  kNoIk,               ///< no IK solution within the joint limits anywhere along the travel
  kNoCollisionFreeIk,  ///< IK solutions exist, every one in collision (self, static or map)
};

/// "feasible", "no_ik" or "no_collision_free_ik" (the latter two as MoveStatus names them).
const char* toString(GoalCheck check);

/// The answer for one pose: its check and, for a feasible one where the arm can tell, the
/// seconds the move would take at least (the straight motion to the configuration the move
/// would go to, timed to the joints' limits); NaN when unknown.
struct GoalReach {
  GoalCheck check = GoalCheck::kFeasible;
  double travel_s = std::numeric_limits<double>::quiet_NaN();
  bool feasible() const { return check == GoalCheck::kFeasible; }
};

/// Checks a batch of camera poses (T_world_camera, the left camera's optical frame) and
/// returns one answer per pose, in order. One call is one compute stage of the robot's: the
/// loop charges it to its clock.
using GoalCheckFn =
    std::function<std::vector<GoalReach>(const std::vector<Eigen::Isometry3d>& T_world_cameras)>;

/// Ranked views checked per call, ahead of the moves. Each call is charged as one compute
/// stage (0.1 s on the fixed clock, its wall time on the wall clock), so a batch should hold
/// the run of failed moves a planning iteration can have on a tree (at most 14 in the 115
/// iterations of development trees 1-3 before the checks) and still cost far less than a
/// fixed-clock stage in wall time (0.6 ms a check on 2 cores; docs/results.md).
inline constexpr std::size_t kDefaultGoalCheckBatch = 16;

}  // namespace fvp::host::planner
