// moveToPose (docs/design.md section 7, docs/robot.md "Motion"): IK along the slider's travel
// -> the valid, collision-free solution soonest reached from the current configuration
// (ArmModel::travelTime_s) -> the straight joint-space motion when it is free, else OMPL
// (RRTConnect by default) in the 7-D joint space with an ArmCollisionChecker behind OMPL's
// StateValidityChecker -> path simplification -> a Trajectory within the velocity and
// acceleration limits. The soonest solution gets a quarter of planning_time_s, sampled in a
// box around the start and the goal; when it cannot be reached (a goal in a pocket of the
// map), every distinct valid solution becomes a goal state for the rest, in the whole joint
// space. Expected failures come back as a MotionStatus; exceptions are for misconfiguration
// only.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "fvp/robot/arm_collision_checker.h"
#include "fvp/robot/trajectory.h"

namespace fvp::robot {

enum class MotionStatus {
  kSuccess,
  kNoIk,               ///< no IK solution within the joint limits at any slider position
  kNoCollisionFreeIk,  ///< solutions exist, all in collision (self, static or map)
  kStartInvalid,       ///< the current configuration itself is in collision or off limits
  kNoPath,             ///< the planner gave up without reaching the goal
  kTimeout,            ///< planning_time_s ran out before a path was found
};

const char* toString(MotionStatus status);

struct MotionPlan {
  MotionStatus status = MotionStatus::kNoPath;
  JointVector goal = JointVector::Zero();  ///< the configuration reached (on success)
  Trajectory trajectory;                   ///< empty unless kSuccess
  double planning_wall_s = 0.0;            ///< IK + planning + simplification + timing
  int ik_solutions = 0;                    ///< within limits, before collision checks
  bool straight = false;  ///< the straight joint-space motion, without a sampling planner
  /// 0, or the waypoint where a move that went back the way the arm came in (ArmConfig
  /// retreat_share) turns onward: the onward path is the way in of the next move.
  std::size_t retreat_turn = 0;
  bool retreated() const { return retreat_turn > 0; }
  /// Every state and motion check of the query (moveToPose: the goals' and every planning
  /// attempt's): the work a fixed clock charges (SimClock::chargeMotionPlanning).
  std::uint64_t validity_checks = 0;
  bool ok() const { return status == MotionStatus::kSuccess; }
};

class MotionPlanner {
 public:
  /// `checker` (and its arm) must outlive the planner; the map is whatever the checker
  /// holds at the time of each call.
  explicit MotionPlanner(const ArmCollisionChecker& checker);

  MotionPlan moveToPose(const JointVector& current, const Eigen::Isometry3d& T_world_camera) const;
  /// moveToPose, knowing `way_in`: the waypoints by which the arm came to `current` (the last
  /// one `current`). When ArmConfig retreat_share is positive and both queries from `current`
  /// fail, the arm may go back that way, checked again on the map it has now, and plan from
  /// where it came from with that share of the budget (taken from the whole-space query's).
  /// Among leaves the arm can stand in a pocket of free space that RRTConnect's long
  /// extensions rarely leave, while the way it came in is open.
  MotionPlan moveToPose(const JointVector& current, const Eigen::Isometry3d& T_world_camera,
                        const std::vector<JointVector>& way_in) const;
  /// moveToPose's first step alone, without motion planning: kNoIk or kNoCollisionFreeIk
  /// exactly when moveToPose from `current` on the same map would fail with that status,
  /// else kSuccess (a collision-free goal exists; the motion may still fail). IK along the
  /// travel and validity checks until the first valid solution: no OMPL, no query number
  /// used, so reproducible planning's later queries are unchanged.
  /// On kSuccess, *goal (when given) is the configuration moveToPose plans to first.
  MotionStatus goalStatus(const JointVector& current, const Eigen::Isometry3d& T_world_camera,
                          JointVector* goal = nullptr) const;

  /// From now on every query is reproducible: OMPL's sampler, planner and path simplifier
  /// are seeded from seed and the query's number, and planning and simplification stop after
  /// a number of validity checks (ArmConfig reproducible_*_checks) instead of a time, so the
  /// same queries on the same map give the same paths on any machine and under any load.
  /// For RRTConnect (the default); other OMPL planners keep their global seeding.
  void setReproducible(std::uint64_t seed);
  /// Planning between two configurations (the goal must be valid).
  MotionPlan planToJoints(const JointVector& current, const JointVector& goal) const;

 private:
  /// The straight motion to the first goal it reaches freely, else one OMPL query to any of
  /// `goals` (all valid) within a share of the budget (time_s, or the same share of the
  /// reproducible check budget), sampling the whole joint space or (local) the box around
  /// the start and the goals.
  MotionPlan plan_(const JointVector& current, const std::vector<JointVector>& goals, double share,
                   bool local) const;
  /// Along `way_back` (checked free) to its last waypoint, then plan_ from there.
  MotionPlan retreatAndPlan_(const std::vector<JointVector>& way_back,
                             const std::vector<JointVector>& goals, double share) const;

  const ArmCollisionChecker& checker_;
  bool reproducible_ = false;
  std::uint64_t seed_ = 0;
  mutable std::uint64_t queries_ = 0;  ///< OMPL queries so far (each gets its own seed)
};

}  // namespace fvp::robot
