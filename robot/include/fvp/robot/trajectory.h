// A time-parameterised joint path, in one of two timings:
// - rest to rest (the constructor): a trapezoidal velocity profile per segment between
//   waypoints, synchronised across joints (every joint starts and stops together and follows
//   the same normalised profile), so the arm stops at every waypoint and never leaves the
//   straight joint-space segments the planner checked;
// - blended (Trajectory::blended): linear segments with parabolic blends (Craig, "Introduction
//   to Robotics", 7.3; the via-point blends of a UR's movej with a blend radius): the arm
//   keeps moving through the via points and cuts each corner, so the path leaves the checked
//   segments near the via points (by at most maxCornerDeviation()) and must be checked again
//   (MotionPlanner does, and falls back to rest to rest).
// Both keep every joint within its velocity and acceleration limits, start at the first
// waypoint and end at the last, at rest.
#pragma once

#include <vector>

#include "fvp/robot/arm_model.h"

namespace fvp::robot {

class Trajectory {
 public:
  Trajectory() = default;
  /// Rest to rest through `waypoints` (at least one) under the per-joint limits.
  Trajectory(std::vector<JointVector> waypoints, const JointVector& max_velocity,
             const JointVector& max_acceleration);
  /// Blended through the via points; rest to rest (isBlended() false) for a single segment,
  /// which is the same timing, or where the blends cannot be fitted.
  static Trajectory blended(std::vector<JointVector> waypoints, const JointVector& max_velocity,
                            const JointVector& max_acceleration);

  /// Blended through the via points but at rest at those flagged in `stops` (one flag per
  /// waypoint; the ends rest anyway): each run between rests timed as blended() times it. A
  /// corner whose blend would collide is passed at rest while the others keep their blends.
  static Trajectory blendedWithStops(std::vector<JointVector> waypoints,
                                     const std::vector<bool>& stops,
                                     const JointVector& max_velocity,
                                     const JointVector& max_acceleration);

  /// The rest-to-rest duration of the straight motion between two configurations (what the
  /// constructor gives for {from, to}), without building it: the time a move costs at least.
  static double restToRestDuration_s(const JointVector& from, const JointVector& to,
                                     const JointVector& max_velocity,
                                     const JointVector& max_acceleration);

  double duration_s() const { return pieces_.empty() ? 0.0 : pieces_.back().end_s(); }
  const std::vector<JointVector>& waypoints() const { return waypoints_; }
  bool empty() const { return waypoints_.empty(); }
  bool isBlended() const { return blended_; }
  /// Position, velocity and acceleration at time t (clamped to [0, duration]).
  JointVector position(double t_s) const;
  JointVector velocity(double t_s) const;
  JointVector acceleration(double t_s) const;
  /// Joint-space path length through the waypoints (sum of segment lengths, jointDistance).
  double pathLength() const;
  /// The largest distance (per joint, rad or m) by which a blend passes a via point; 0 for
  /// rest to rest.
  double maxCornerDeviation() const { return max_corner_deviation_; }

 private:
  /// Constant acceleration over [start_s, start_s + duration_s].
  struct Piece {
    double start_s = 0.0, duration_s = 0.0;
    JointVector q0 = JointVector::Zero(), v0 = JointVector::Zero(), a = JointVector::Zero();
    double end_s() const { return start_s + duration_s; }
  };
  const Piece& pieceAt(double t_s, double& tau) const;
  void addPiece(double duration_s, const JointVector& q0, const JointVector& v0,
                const JointVector& a);

  std::vector<JointVector> waypoints_;
  std::vector<Piece> pieces_;
  bool blended_ = false;
  double max_corner_deviation_ = 0.0;
};

}  // namespace fvp::robot
