#include "fvp/robot/trajectory.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace fvp::robot {

void Trajectory::addPiece(double duration_s, const JointVector& q0, const JointVector& v0,
                          const JointVector& a) {
  if (!(duration_s > 0.0)) return;
  Piece p;
  p.start_s = pieces_.empty() ? 0.0 : pieces_.back().end_s();
  p.duration_s = duration_s;
  p.q0 = q0, p.v0 = v0, p.a = a;
  pieces_.push_back(p);
}

namespace {

/// One rest-to-rest segment's normalised profile s(t) in [0, 1], which moves joint j by
/// delta_j * s: its rate and acceleration bounded by the tightest joint; ramp up, cruise
/// (zero when the peak rate is never reached), ramp down.
struct SegmentProfile {
  double a = 0.0, v_peak = 0.0, ramp_s = 0.0, cruise_s = 0.0;
  bool moves = false;  ///< false for a zero-length segment, which takes no time
  double duration_s() const { return 2.0 * ramp_s + cruise_s; }
};

SegmentProfile segmentProfile(const JointVector& delta, const JointVector& max_velocity,
                              const JointVector& max_acceleration) {
  double v = std::numeric_limits<double>::infinity(), a = v;
  for (int j = 0; j < kArmJoints; ++j) {
    if (delta[j] <= 0.0) continue;
    v = std::min(v, max_velocity[j] / delta[j]);
    a = std::min(a, max_acceleration[j] / delta[j]);
  }
  SegmentProfile p;
  if (!std::isfinite(v)) return p;
  p.moves = true;
  p.a = a;
  if (v * v / a >= 1.0) {  // triangular: the peak rate is never reached
    p.ramp_s = std::sqrt(1.0 / a);
    p.v_peak = a * p.ramp_s;
  } else {
    p.ramp_s = v / a;
    p.v_peak = v;
    p.cruise_s = 1.0 / v - v / a;
  }
  return p;
}

}  // namespace

double Trajectory::restToRestDuration_s(const JointVector& from, const JointVector& to,
                                        const JointVector& max_velocity,
                                        const JointVector& max_acceleration) {
  return segmentProfile((to - from).cwiseAbs(), max_velocity, max_acceleration).duration_s();
}

Trajectory::Trajectory(std::vector<JointVector> waypoints, const JointVector& max_velocity,
                       const JointVector& max_acceleration)
    : waypoints_(std::move(waypoints)) {
  if (waypoints_.empty()) throw std::invalid_argument("Trajectory: no waypoints");
  for (std::size_t i = 0; i + 1 < waypoints_.size(); ++i) {
    const JointVector d = waypoints_[i + 1] - waypoints_[i];
    const SegmentProfile p = segmentProfile(d.cwiseAbs(), max_velocity, max_acceleration);
    if (!p.moves) continue;
    const double s_ramp = 0.5 * p.a * p.ramp_s * p.ramp_s;
    addPiece(p.ramp_s, waypoints_[i], JointVector::Zero(), p.a * d);
    addPiece(p.cruise_s, waypoints_[i] + s_ramp * d, p.v_peak * d, JointVector::Zero());
    addPiece(p.ramp_s, waypoints_[i + 1] - s_ramp * d, p.v_peak * d, -p.a * d);
  }
}

Trajectory Trajectory::blended(std::vector<JointVector> waypoints, const JointVector& max_velocity,
                               const JointVector& max_acceleration) {
  if (waypoints.empty()) throw std::invalid_argument("Trajectory: no waypoints");
  // Zero-length segments have no direction to blend.
  std::vector<JointVector> q{waypoints.front()};
  for (const auto& w : waypoints)
    if ((w - q.back()).cwiseAbs().maxCoeff() > 0.0) q.push_back(w);
  const std::size_t n = q.size() - 1;  // segments
  if (n < 2) return Trajectory(std::move(waypoints), max_velocity, max_acceleration);

  // Segment i runs from knot i to knot i + 1 in T[i] along its line (velocity v[i]); the
  // blend at knot k takes tb[k], centred on it, at the acceleration that turns v[k - 1] into
  // v[k] (rest before the first knot and after the last). Start at full speed on the
  // tightest joint, and lengthen segments whose blends overlap.
  std::vector<double> T(n);
  for (std::size_t i = 0; i < n; ++i)
    T[i] = ((q[i + 1] - q[i]).cwiseAbs().cwiseQuotient(max_velocity)).maxCoeff();
  std::vector<JointVector> v(n);
  std::vector<double> tb(n + 1);
  const auto blends = [&] {
    for (std::size_t i = 0; i < n; ++i) v[i] = (q[i + 1] - q[i]) / T[i];
    for (std::size_t k = 0; k <= n; ++k) {
      const JointVector before = k == 0 ? JointVector::Zero() : v[k - 1];
      const JointVector after = k == n ? JointVector::Zero() : v[k];
      tb[k] = ((after - before).cwiseAbs().cwiseQuotient(max_acceleration)).maxCoeff();
    }
  };
  bool fits = false;
  for (int iteration = 0; iteration < 200 && !fits; ++iteration) {
    blends();
    fits = true;
    for (std::size_t i = 0; i < n; ++i) {
      const double needed = 0.5 * (tb[i] + tb[i + 1]);
      if (T[i] >= needed * (1.0 - 1e-12)) continue;
      fits = false;
      // The geometric mean lands on the optimum at once for a lone segment (T = sqrt(d/a))
      // and converges for chains; never shorter than needed times a hair, to terminate.
      T[i] = std::max(std::sqrt(T[i] * needed), T[i] * (1.0 + 1e-9));
    }
  }
  if (!fits) return Trajectory(std::move(waypoints), max_velocity, max_acceleration);

  Trajectory traj;
  traj.waypoints_ = std::move(waypoints);
  traj.blended_ = true;
  // A segment's line passes its knots. Pieces: the blend at knot 0, then
  // for each segment its straight part and the blend at its end knot.
  for (std::size_t k = 0; k <= n; ++k) {
    const JointVector before = k == 0 ? JointVector::Zero() : v[k - 1];
    const JointVector after = k == n ? JointVector::Zero() : v[k];
    if (tb[k] > 0.0) {
      const JointVector a = (after - before) / tb[k];
      // On the incoming line (at rest at q[0] before the first knot), half a blend early.
      traj.addPiece(tb[k], q[k] - 0.5 * tb[k] * before, before, a);
      if (k > 0 && k < n)  // a blend misses its knot by |dv| tb / 8
        traj.max_corner_deviation_ = std::max(traj.max_corner_deviation_,
                                              (after - before).cwiseAbs().maxCoeff() * tb[k] / 8.0);
    }
    if (k == n) break;
    const double straight_s = std::max(0.0, T[k] - 0.5 * tb[k] - 0.5 * tb[k + 1]);
    traj.addPiece(straight_s, q[k] + 0.5 * tb[k] * v[k], v[k], JointVector::Zero());
  }
  return traj;
}

Trajectory Trajectory::blendedWithStops(std::vector<JointVector> waypoints,
                                        const std::vector<bool>& stops,
                                        const JointVector& max_velocity,
                                        const JointVector& max_acceleration) {
  if (waypoints.empty()) throw std::invalid_argument("Trajectory: no waypoints");
  if (stops.size() != waypoints.size())
    throw std::invalid_argument("Trajectory: one stop flag per waypoint expected");
  Trajectory traj;
  std::size_t from = 0;
  for (std::size_t k = 1; k < waypoints.size(); ++k) {
    if (k + 1 < waypoints.size() && !stops[k]) continue;
    const Trajectory run = blended({waypoints.begin() + from, waypoints.begin() + k + 1},
                                   max_velocity, max_acceleration);
    for (const Piece& p : run.pieces_) traj.addPiece(p.duration_s, p.q0, p.v0, p.a);
    traj.blended_ = traj.blended_ || run.blended_;
    traj.max_corner_deviation_ = std::max(traj.max_corner_deviation_, run.max_corner_deviation_);
    from = k;
  }
  traj.waypoints_ = std::move(waypoints);
  return traj;
}

const Trajectory::Piece& Trajectory::pieceAt(double t_s, double& tau) const {
  const auto it = std::lower_bound(pieces_.begin(), pieces_.end(), t_s,
                                   [](const Piece& p, double t) { return p.end_s() < t; });
  const Piece& p = it == pieces_.end() ? pieces_.back() : *it;
  tau = std::clamp(t_s - p.start_s, 0.0, p.duration_s);
  return p;
}

JointVector Trajectory::position(double t_s) const {
  // The ends exactly (a goal on a joint limit must not land an ulp beyond it).
  if (waypoints_.empty()) return JointVector::Zero();
  if (pieces_.empty() || t_s >= duration_s()) return waypoints_.back();
  if (t_s <= 0.0) return waypoints_.front();
  double tau;
  const Piece& p = pieceAt(t_s, tau);
  return p.q0 + tau * p.v0 + 0.5 * tau * tau * p.a;
}

JointVector Trajectory::velocity(double t_s) const {
  if (pieces_.empty()) return JointVector::Zero();
  double tau;
  const Piece& p = pieceAt(t_s, tau);
  if (t_s >= duration_s() || t_s <= 0.0) return JointVector::Zero();
  return p.v0 + tau * p.a;
}

JointVector Trajectory::acceleration(double t_s) const {
  if (pieces_.empty()) return JointVector::Zero();
  double tau;
  return pieceAt(t_s, tau).a;
}

double Trajectory::pathLength() const {
  double length = 0.0;
  for (std::size_t i = 0; i + 1 < waypoints_.size(); ++i)
    length += jointDistance(waypoints_[i], waypoints_[i + 1]);
  return length;
}

}  // namespace fvp::robot
