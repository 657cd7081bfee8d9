// The next-best-view loop's arm for a UR5 on its slider, real or simulated: the planning side
// is fvp's (reachability from a workspace tree, IK + OMPL motion planning against the live
// coarse map), the motion is the driver's. Each moveTo reads the joints from a
// JointStateSource, plans from them with MotionPlanner, and hands the Trajectory to a
// TrajectoryExecutor; afterwards the joints must be at the trajectory's end. Poses are the
// left camera's optical frame in the world (T_world_camera, ArmModel). Expected failures
// (no IK, no path, a refused or failed execution) are MoveStatus values; exceptions are for
// misconfiguration (a joint state that is not finite, a bad tolerance, a broken executor).
// Not thread-safe: one loop drives it.
#pragma once

#include <cstdint>
#include <functional>

#include "fvp/host/nbv/arm.h"
#include "fvp/robot/arm_collision_checker.h"
#include "fvp/robot/joint_state_source.h"
#include "fvp/robot/motion_planner.h"
#include "fvp/robot/reachability.h"
#include "fvp/robot/trajectory_executor.h"

namespace octomap {
class OcTree;
}

namespace fvp::robot {

/// One move: the plan, what the executor said (when the plan succeeded), the outcome.
struct PlannedMove {
  host::nbv::MoveStatus status = host::nbv::MoveStatus::kNoPath;
  MotionPlan plan;
  ExecutionResult execution;  ///< kFailed with no detail when nothing was executed
  host::nbv::MoveResult result() const {
    const bool moved = status == host::nbv::MoveStatus::kSuccess;
    return {status, plan.planning_wall_s, moved ? plan.trajectory.duration_s() : 0.0,
            moved && plan.retreated()};
  }
};

/// How far (per joint, rad or m for the slider) the joints may be from the trajectory's
/// end after an execution reported done: a UR5 settles well within 1 mrad.
inline constexpr double kDefaultGoalTolerance = 0.005;

class PlannedArm : public host::nbv::Arm {
 public:
  /// Called after every planning attempt, failed ones included, before any execution (the
  /// simulator charges plan.planning_wall_s to its clock here).
  using PlanningObserver = std::function<void(const MotionPlan& plan)>;

  /// Every reference must outlive the arm. Throws std::invalid_argument for a goal tolerance
  /// that is not positive.
  PlannedArm(const ArmModel& arm, const Reachability& reachability, JointStateSource& joint_state,
             TrajectoryExecutor& executor, double goal_tolerance = kDefaultGoalTolerance);

  Eigen::Isometry3d cameraPose() const override;
  bool reachable(const Eigen::Isometry3d& T_world_camera) const override;
  host::nbv::MoveResult moveTo(const Eigen::Isometry3d& T_world_camera) override;
  bool checksGoals() const override { return true; }
  /// MotionPlanner::goalStatus from the joints now, on the map of the last setMap: IK along
  /// the travel and collision checks (self, static, FCL against the map), no OMPL.
  host::planner::GoalReach checkGoal(const Eigen::Isometry3d& T_world_camera) const override;
  /// ArmModel::travelTime_s between the goals goalStatus picks: `from`'s from the joints now
  /// (the joints themselves when the camera is there), `to`'s from `from`'s.
  double travelTime_s(const Eigen::Isometry3d& T_world_from_camera,
                      const Eigen::Isometry3d& T_world_to_camera) const override;
  /// setMap with the map's coarse octree.
  std::size_t updateObstacles(host::map::MapEngine& map) override;

  /// moveTo with the plan and the executor's answer.
  PlannedMove moveToPose(const Eigen::Isometry3d& T_world_camera);
  /// From now on planning avoids this coarse map (copied), less the voxels the arm occupies
  /// at its current joints (ArmCollisionChecker::setMapFreeAt); returns how many those were.
  std::size_t setMap(const octomap::OcTree& coarse_map);
  /// MotionPlanner::setReproducible: the same moves on any machine and under any load.
  void setReproducibleMotionPlanning(std::uint64_t seed) { planner_.setReproducible(seed); }
  void setPlanningObserver(PlanningObserver observer) { observer_ = std::move(observer); }

  /// The joint state source's joints, checked finite (std::runtime_error otherwise).
  JointVector joints() const;
  const ArmModel& model() const { return arm_; }
  const ArmCollisionChecker& checker() const { return checker_; }
  double goalTolerance() const { return goal_tolerance_; }

 private:
  const ArmModel& arm_;
  const Reachability& reachability_;
  JointStateSource& joint_state_;
  TrajectoryExecutor& executor_;
  double goal_tolerance_;
  ArmCollisionChecker checker_;
  MotionPlanner planner_;
  PlanningObserver observer_;
  /// The waypoints of the last move done, from where it turned onward, ending where the arm
  /// stood after it (empty after a move that failed): the way back that the planner may take
  /// (MotionPlanner::moveToPose's way_in).
  std::vector<JointVector> way_in_;
};

/// MotionStatus -> the loop's MoveStatus (the planning failures keep their names).
host::nbv::MoveStatus toMoveStatus(MotionStatus status);

}  // namespace fvp::robot
