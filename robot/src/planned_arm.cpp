#include "fvp/robot/planned_arm.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "fvp/host/map/map_engine.h"

namespace fvp::robot {

host::nbv::MoveStatus toMoveStatus(MotionStatus status) {
  using host::nbv::MoveStatus;
  switch (status) {
    case MotionStatus::kSuccess:
      return MoveStatus::kSuccess;
    case MotionStatus::kNoIk:
      return MoveStatus::kNoIk;
    case MotionStatus::kNoCollisionFreeIk:
      return MoveStatus::kNoCollisionFreeIk;
    case MotionStatus::kStartInvalid:
      return MoveStatus::kStartInvalid;
    case MotionStatus::kNoPath:
      return MoveStatus::kNoPath;
    case MotionStatus::kTimeout:
      return MoveStatus::kTimeout;
  }
  return MoveStatus::kNoPath;
}

PlannedArm::PlannedArm(const ArmModel& arm, const Reachability& reachability,
                       JointStateSource& joint_state, TrajectoryExecutor& executor,
                       double goal_tolerance)
    : arm_(arm),
      reachability_(reachability),
      joint_state_(joint_state),
      executor_(executor),
      goal_tolerance_(goal_tolerance),
      checker_(arm),
      planner_(checker_) {
  if (!(goal_tolerance > 0.0) || !std::isfinite(goal_tolerance))
    throw std::invalid_argument("PlannedArm: the goal tolerance must be positive and finite");
}

JointVector PlannedArm::joints() const {
  const JointVector q = joint_state_.jointPositions();
  // A source with no reading yet is a setup error: planning from NaN would mean nothing.
  if (!q.allFinite())
    throw std::runtime_error("PlannedArm: the joint state source gave a joint that is not finite");
  return q;
}

Eigen::Isometry3d PlannedArm::cameraPose() const {
  return arm_.T_world_camera(joints());
}

bool PlannedArm::reachable(const Eigen::Isometry3d& T_world_camera) const {
  return reachability_.reachable(T_world_camera);
}

host::planner::GoalReach PlannedArm::checkGoal(const Eigen::Isometry3d& T_world_camera) const {
  using host::planner::GoalCheck;
  const JointVector current = joints();
  JointVector goal;
  switch (planner_.goalStatus(current, T_world_camera, &goal)) {
    case MotionStatus::kNoIk:
      return {GoalCheck::kNoIk};
    case MotionStatus::kNoCollisionFreeIk:
      return {GoalCheck::kNoCollisionFreeIk};
    case MotionStatus::kSuccess:
    case MotionStatus::kStartInvalid:
    case MotionStatus::kNoPath:
    case MotionStatus::kTimeout:
      break;
  }
  // The goal moveToPose plans to first; the straight motion to it, the least the move takes.
  return {GoalCheck::kFeasible, arm_.travelTime_s(current, goal)};
}

double PlannedArm::travelTime_s(const Eigen::Isometry3d& T_world_from_camera,
                                const Eigen::Isometry3d& T_world_to_camera) const {
  constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();
  const JointVector current = joints();
  JointVector from = current, to;
  if (!arm_.T_world_camera(current).isApprox(T_world_from_camera, 1e-9) &&
      planner_.goalStatus(current, T_world_from_camera, &from) != MotionStatus::kSuccess)
    return kUnknown;
  if (planner_.goalStatus(from, T_world_to_camera, &to) != MotionStatus::kSuccess) return kUnknown;
  return arm_.travelTime_s(from, to);
}

host::nbv::MoveResult PlannedArm::moveTo(const Eigen::Isometry3d& T_world_camera) {
  return moveToPose(T_world_camera).result();
}

PlannedMove PlannedArm::moveToPose(const Eigen::Isometry3d& T_world_camera) {
  PlannedMove move;
  move.plan = planner_.moveToPose(joints(), T_world_camera, way_in_);
  if (observer_) observer_(move.plan);
  move.status = toMoveStatus(move.plan.status);
  if (!move.plan.ok()) return move;
  // Until this move is done the arm is not where a way in would end (a refused one: it is).
  std::vector<JointVector> way_in = std::move(way_in_);
  way_in_.clear();
  move.execution = executor_.execute(move.plan.trajectory);
  switch (move.execution.status) {
    case ExecutionStatus::kRefused:
      way_in_ = std::move(way_in);
      move.status = host::nbv::MoveStatus::kRefused;
      return move;
    case ExecutionStatus::kFailed:
      move.status = host::nbv::MoveStatus::kExecutionFailed;
      return move;
    case ExecutionStatus::kDone:
      break;
  }
  // "Done" is the driver's word; the joints say whether the arm is where it was sent.
  const JointVector error = joints() - move.plan.trajectory.waypoints().back();
  if (error.cwiseAbs().maxCoeff() > goal_tolerance_) {
    move.status = host::nbv::MoveStatus::kExecutionFailed;
    move.execution.status = ExecutionStatus::kFailed;
    move.execution.detail = "the executor reported done, but a joint is " +
                            std::to_string(error.cwiseAbs().maxCoeff()) +
                            " (rad or m) from the trajectory's end";
    return move;
  }
  // The way in of the next move: from where this one turned onward (going back into a pocket
  // it left is no way out), ending where the arm stands (within the driver's tolerance).
  const std::vector<JointVector>& w = move.plan.trajectory.waypoints();
  way_in_.assign(w.begin() + static_cast<std::ptrdiff_t>(move.plan.retreat_turn), w.end());
  way_in_.back() = joints();
  return move;
}

std::size_t PlannedArm::setMap(const octomap::OcTree& coarse_map) {
  return checker_.setMapFreeAt(coarse_map, joints());
}

std::size_t PlannedArm::updateObstacles(host::map::MapEngine& map) {
  return setMap(map.coarseOcTree());
}

}  // namespace fvp::robot
