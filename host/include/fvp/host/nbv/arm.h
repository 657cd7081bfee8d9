// The arm the next-best-view loop moves the camera with (a real arm's driver and planner,
// or the simulated UR5 on its slider). Failures to move are statuses, never exceptions.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <limits>
#include <string>

#include "fvp/host/planner/goal_check.h"

namespace fvp::host::map {
class MapEngine;
}

namespace fvp::host::nbv {

enum class MoveStatus {
  kSuccess,
  kNoIk,               ///< no inverse-kinematics solution for the pose
  kNoCollisionFreeIk,  ///< solutions exist, all in collision
  kStartInvalid,       ///< the current configuration is in collision or off limits
  kNoPath,             ///< the motion planner gave up
  kTimeout,            ///< planning ran out of time
  kRefused,            ///< the arm's driver or its operator refused the motion
  kExecutionFailed,    ///< the motion started but did not reach the goal
};

/// "success", "no_ik", ... (the keys of result.json's events.motion_status).
const char* toString(MoveStatus status);

struct MoveResult {
  MoveStatus status = MoveStatus::kNoPath;
  double planning_wall_s = 0.0;  ///< wall time spent planning the motion (for reports)
  /// The arm's time in motion: the executed trajectory's duration (0 when it did not move,
  /// or for an arm that does not say).
  double motion_s = 0.0;
  /// The move first went back the way the arm came in (robot::ArmConfig::retreat_share).
  bool retreated = false;
  bool ok() const { return status == MoveStatus::kSuccess; }
};

class Arm {
 public:
  virtual ~Arm() = default;
  /// The left camera's optical-frame pose in the world, now.
  virtual Eigen::Isometry3d cameraPose() const = 0;
  /// Whether the camera can be put at this pose at all; cheap, may be optimistic. The
  /// planner only sends reachable candidates to moveTo.
  virtual bool reachable(const Eigen::Isometry3d& T_world_camera) const = 0;
  /// Plans and executes a move of the camera to the pose (blocking).
  virtual MoveResult moveTo(const Eigen::Isometry3d& T_world_camera) = 0;
  /// Whether the arm answers checkGoal; the loop asks only an arm that does (and charges the
  /// checks to its clock). false: every ranked view goes straight to moveTo.
  virtual bool checksGoals() const { return false; }
  /// From where the arm is, on the map of the last updateObstacles: the part of moveTo that
  /// needs no motion planning (IK, then one solution free of collision). kFeasible means
  /// moveTo will plan a motion (which may still fail); the others mean moveTo would fail with
  /// the MoveStatus of the same name. Much cheaper than a move (no motion planning, nothing
  /// executed), so the loop checks the top of each ranking before it tries a move.
  /// A feasible answer's travel_s is the least the move takes (GoalReach), NaN if unknown.
  virtual planner::GoalReach checkGoal(const Eigen::Isometry3d& T_world_camera) const {
    (void)T_world_camera;
    return {};
  }
  /// The least time the arm takes from one camera pose to another: the straight joint-space
  /// motion between the configurations it would take there (each the one moveTo would go to,
  /// `from` reached from where the arm is now), on the map of the last updateObstacles. NaN
  /// when unknown or when either pose has no collision-free IK. The tour orders clusters by it.
  virtual double travelTime_s(const Eigen::Isometry3d& T_world_from_camera,
                              const Eigen::Isometry3d& T_world_to_camera) const {
    (void)T_world_from_camera;
    (void)T_world_to_camera;
    return std::numeric_limits<double>::quiet_NaN();
  }
  /// Called after new views reached the map, before planning, so the arm avoids what the
  /// camera has seen. Returns a count for the log (the simulated arm: voxels it freed where
  /// it stands); 0 for an arm that does not use the map.
  virtual std::size_t updateObstacles(map::MapEngine& map) {
    (void)map;
    return 0;
  }
};

}  // namespace fvp::host::nbv
