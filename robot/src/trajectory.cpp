#include "fvp/robot/trajectory.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace fvp::robot {

Trajectory::Trajectory(std::vector<JointVector> waypoints, const JointVector& max_velocity,
                       const JointVector& max_acceleration)
    : waypoints_(std::move(waypoints)) {
  if (waypoints_.empty()) throw std::invalid_argument("Trajectory: no waypoints");
  double t = 0.0;
  for (std::size_t i = 0; i + 1 < waypoints_.size(); ++i) {
    const JointVector delta = (waypoints_[i + 1] - waypoints_[i]).cwiseAbs();
    // The normalised profile s(t) in [0, 1] moves joint j by delta_j * s: its rate and
    // acceleration are bounded by the tightest joint.
    double v = std::numeric_limits<double>::infinity(), a = v;
    for (int j = 0; j < kArmJoints; ++j) {
      if (delta[j] <= 0.0) continue;
      v = std::min(v, max_velocity[j] / delta[j]);
      a = std::min(a, max_acceleration[j] / delta[j]);
    }
    Segment seg;
    seg.start_s = t;
    if (std::isfinite(v)) {
      if (v * v / a >= 1.0) {  // triangular: the peak rate is never reached
        seg.ramp_s = std::sqrt(1.0 / a);
        seg.v_norm = a * seg.ramp_s;
        seg.duration_s = 2.0 * seg.ramp_s;
      } else {
        seg.ramp_s = v / a;
        seg.v_norm = v;
        seg.duration_s = 1.0 / v + v / a;
      }
      seg.a_norm = a;
    }
    t += seg.duration_s;
    segments_.push_back(seg);
    end_times_s_.push_back(t);
  }
}

void Trajectory::profile(const Segment& seg, double tau, double& s, double& ds, double& dds) {
  if (seg.duration_s <= 0.0) {
    s = 1.0;
    ds = dds = 0.0;
    return;
  }
  tau = std::clamp(tau, 0.0, seg.duration_s);
  const double a = seg.a_norm, v = seg.v_norm, r = seg.ramp_s, T = seg.duration_s;
  if (tau < r) {
    s = 0.5 * a * tau * tau, ds = a * tau, dds = a;
  } else if (tau <= T - r) {
    s = 0.5 * a * r * r + v * (tau - r), ds = v, dds = 0.0;
  } else {
    const double left = T - tau;
    s = 1.0 - 0.5 * a * left * left, ds = a * left, dds = -a;
  }
}

int Trajectory::segmentAt(double t_s) const {
  const auto it = std::lower_bound(end_times_s_.begin(), end_times_s_.end(), t_s);
  return static_cast<int>(std::min<std::ptrdiff_t>(
      it - end_times_s_.begin(), static_cast<std::ptrdiff_t>(segments_.size()) - 1));
}

JointVector Trajectory::position(double t_s) const {
  if (segments_.empty()) return waypoints_.front();
  const int i = segmentAt(t_s);
  double s, ds, dds;
  profile(segments_[i], t_s - segments_[i].start_s, s, ds, dds);
  return waypoints_[i] + s * (waypoints_[i + 1] - waypoints_[i]);
}

JointVector Trajectory::velocity(double t_s) const {
  if (segments_.empty()) return JointVector::Zero();
  const int i = segmentAt(t_s);
  double s, ds, dds;
  profile(segments_[i], t_s - segments_[i].start_s, s, ds, dds);
  return ds * (waypoints_[i + 1] - waypoints_[i]);
}

JointVector Trajectory::acceleration(double t_s) const {
  if (segments_.empty()) return JointVector::Zero();
  const int i = segmentAt(t_s);
  double s, ds, dds;
  profile(segments_[i], t_s - segments_[i].start_s, s, ds, dds);
  return dds * (waypoints_[i + 1] - waypoints_[i]);
}

double Trajectory::pathLength() const {
  double length = 0.0;
  for (std::size_t i = 0; i + 1 < waypoints_.size(); ++i)
    length += jointDistance(waypoints_[i], waypoints_[i + 1]);
  return length;
}

}  // namespace fvp::robot
