// A time-parameterised joint path: rest-to-rest trapezoidal velocity profiles per segment
// between waypoints, synchronised across joints (every joint starts and stops together and
// follows the same normalised profile), so no joint exceeds its velocity or acceleration
// limit.
#pragma once

#include <vector>

#include "fvp/robot/arm_model.h"

namespace fvp::robot {

class Trajectory {
 public:
  Trajectory() = default;
  /// Times the path through `waypoints` (at least one) under the per-joint limits.
  Trajectory(std::vector<JointVector> waypoints, const JointVector& max_velocity,
             const JointVector& max_acceleration);

  double duration_s() const { return end_times_s_.empty() ? 0.0 : end_times_s_.back(); }
  const std::vector<JointVector>& waypoints() const { return waypoints_; }
  bool empty() const { return waypoints_.empty(); }
  /// Position, velocity and acceleration at time t (clamped to [0, duration]).
  JointVector position(double t_s) const;
  JointVector velocity(double t_s) const;
  JointVector acceleration(double t_s) const;
  /// Joint-space path length (sum of segment lengths, jointDistance).
  double pathLength() const;

 private:
  struct Segment {
    double start_s = 0.0, duration_s = 0.0;
    double v_norm = 0.0, a_norm = 0.0;  ///< peak rate and acceleration of s in [0, 1]
    double ramp_s = 0.0;                ///< duration of the acceleration ramp
  };
  int segmentAt(double t_s) const;
  // s(t), s'(t), s''(t) of a segment's normalised profile at local time tau.
  static void profile(const Segment& seg, double tau, double& s, double& ds, double& dds);

  std::vector<JointVector> waypoints_;
  std::vector<Segment> segments_;
  std::vector<double> end_times_s_;
};

}  // namespace fvp::robot
