// Time parameterisation: limits respected everywhere, waypoints reached, joints synchronised.
#include <gtest/gtest.h>

#include <random>

#include "fvp/robot/trajectory.h"

namespace fvp::robot {
namespace {

TEST(Trajectory, NeverExceedsLimitsAndPassesEveryWaypoint) {
  const ArmModel arm{ArmConfig{}};
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<JointVector> waypoints;
    const int n = 2 + trial % 6;
    for (int i = 0; i < n; ++i) {
      JointVector q;
      for (int j = 0; j < kArmJoints; ++j) q[j] = (j == 0 ? 0.5 : 2.0) * unit(rng);
      if (trial % 7 == 0 && i > 0) q = waypoints.back();  // zero-length segments too
      waypoints.push_back(q);
    }
    const Trajectory traj(waypoints, arm.maxVelocity(), arm.maxAcceleration());
    EXPECT_LT((traj.position(0.0) - waypoints.front()).norm(), 1e-12);
    EXPECT_LT((traj.position(traj.duration_s()) - waypoints.back()).norm(), 1e-9);
    const int steps = 4000;
    const double dt = traj.duration_s() / steps;
    for (int k = 0; k <= steps; ++k) {
      const double t = k * dt;
      const JointVector v = traj.velocity(t), a = traj.acceleration(t);
      for (int j = 0; j < kArmJoints; ++j) {
        ASSERT_LE(std::abs(v[j]), arm.maxVelocity()[j] * (1.0 + 1e-9))
            << "t " << t << " joint " << j;
        ASSERT_LE(std::abs(a[j]), arm.maxAcceleration()[j] * (1.0 + 1e-9))
            << "t " << t << " joint " << j;
      }
      // Velocity is the derivative of position (central differences).
      if (k > 0 && k < steps) {
        const JointVector fd = (traj.position(t + 1e-6) - traj.position(t - 1e-6)) / 2e-6;
        ASSERT_LT((fd - v).norm(), 1e-4) << "t " << t;
      }
    }
    // Synchronised: every sample lies on the straight joint-space segment it is on.
    for (int k = 0; k <= 200; ++k) {
      const JointVector q = traj.position(k * traj.duration_s() / 200);
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i + 1 < waypoints.size(); ++i) {
        const JointVector d = waypoints[i + 1] - waypoints[i];
        const double s = d.squaredNorm() > 0
                             ? std::clamp((q - waypoints[i]).dot(d) / d.squaredNorm(), 0.0, 1.0)
                             : 0.0;
        best = std::min(best, (waypoints[i] + s * d - q).norm());
      }
      ASSERT_LT(best, 1e-9);
    }
  }
}

TEST(Trajectory, MinimumTimeForOneJoint) {
  const ArmModel arm{ArmConfig{}};
  JointVector a = JointVector::Zero(), b = JointVector::Zero();
  b[1] = 0.5;  // 0.5 rad: triangular at 1.4 rad/s^2 (v peak sqrt(0.7) < pi)
  const Trajectory short_move({a, b}, arm.maxVelocity(), arm.maxAcceleration());
  EXPECT_NEAR(short_move.duration_s(), 2.0 * std::sqrt(0.5 / 1.4), 1e-12);
  b[1] = 10.0;  // long: trapezoid, 10/pi + pi/1.4
  const Trajectory long_move({a, b}, arm.maxVelocity(), arm.maxAcceleration());
  EXPECT_NEAR(long_move.duration_s(), 10.0 / std::numbers::pi + std::numbers::pi / 1.4, 1e-12);
  // The duration without the trajectory: the same numbers.
  b[1] = 0.5;
  EXPECT_DOUBLE_EQ(Trajectory::restToRestDuration_s(a, b, arm.maxVelocity(), arm.maxAcceleration()),
                   short_move.duration_s());
  EXPECT_DOUBLE_EQ(arm.travelTime_s(b, a), short_move.duration_s());
  EXPECT_EQ(arm.travelTime_s(a, a), 0.0);
  const Trajectory still({a}, arm.maxVelocity(), arm.maxAcceleration());
  EXPECT_EQ(still.duration_s(), 0.0);
  EXPECT_EQ(still.position(1.0), a);
}

TEST(Trajectory, BlendedKeepsTheLimitsPassesNearTheViaPointsAndIsNeverSlower) {
  const ArmModel arm{ArmConfig{}};
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int blended = 0;
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<JointVector> waypoints;
    const int n = 2 + trial % 6;
    for (int i = 0; i < n; ++i) {
      JointVector q;
      for (int j = 0; j < kArmJoints; ++j)
        q[j] = (j == 0 ? 0.5 : (trial % 2 ? 0.2 : 2.0)) * unit(rng);
      if (trial % 7 == 0 && i > 0) q = waypoints.back();  // zero-length segments too
      waypoints.push_back(q);
    }
    const Trajectory rest(waypoints, arm.maxVelocity(), arm.maxAcceleration());
    const Trajectory traj =
        Trajectory::blended(waypoints, arm.maxVelocity(), arm.maxAcceleration());
    blended += traj.isBlended();
    EXPECT_LE(traj.duration_s(), rest.duration_s() * (1.0 + 1e-9)) << "trial " << trial;
    // Starts and ends on the path's ends, at rest.
    EXPECT_LT((traj.position(0.0) - waypoints.front()).norm(), 1e-12);
    EXPECT_LT((traj.position(traj.duration_s()) - waypoints.back()).norm(), 1e-9);
    EXPECT_LT(traj.velocity(0.0).norm(), 1e-12);
    const int steps = 4000;
    const double dt = traj.duration_s() / steps;
    std::vector<JointVector> samples;
    for (int k = 0; k <= steps; ++k) {
      const double t = k * dt;
      const JointVector v = traj.velocity(t), a = traj.acceleration(t);
      for (int j = 0; j < kArmJoints; ++j) {
        ASSERT_LE(std::abs(v[j]), arm.maxVelocity()[j] * (1.0 + 1e-9)) << "t " << t;
        ASSERT_LE(std::abs(a[j]), arm.maxAcceleration()[j] * (1.0 + 1e-9)) << "t " << t;
      }
      if (k > 0 && k < steps) {  // continuous, and v its derivative
        const JointVector fd = (traj.position(t + 1e-6) - traj.position(t - 1e-6)) / 2e-6;
        ASSERT_LT((fd - v).norm(), 1e-4) << "t " << t;
      }
      samples.push_back(traj.position(t));
      // No jump between pieces: no joint moves faster than its limit between samples.
      for (int j = 0; k > 0 && j < kArmJoints; ++j) {
        ASSERT_LE(std::abs(samples[k][j] - samples[k - 1][j]),
                  arm.maxVelocity()[j] * dt * (1.0 + 1e-6) + 1e-12)
            << "t " << t << " joint " << j;
      }
    }
    // Every via point is passed within the stated corner deviation (per joint).
    const double tolerance = traj.maxCornerDeviation() + 1e-9;
    for (std::size_t i = 1; i + 1 < waypoints.size(); ++i) {
      double nearest = std::numeric_limits<double>::infinity();
      for (const auto& q : samples)
        nearest = std::min(nearest, (q - waypoints[i]).cwiseAbs().maxCoeff());
      // Sampling adds at most the distance moved in half a step.
      EXPECT_LE(nearest, tolerance + 0.5 * dt * arm.maxVelocity().maxCoeff()) << "via " << i;
    }
    if (!traj.isBlended()) {
      EXPECT_EQ(traj.duration_s(), rest.duration_s());
    }
  }
  EXPECT_GT(blended, 30);
}

TEST(Trajectory, BlendedOneSegmentIsRestToRestAndACornerIsFaster) {
  const ArmModel arm{ArmConfig{}};
  JointVector a = JointVector::Zero(), b = a, c = a;
  b[1] = 0.5;
  const Trajectory one = Trajectory::blended({a, b}, arm.maxVelocity(), arm.maxAcceleration());
  EXPECT_FALSE(one.isBlended());
  EXPECT_NEAR(one.duration_s(), 2.0 * std::sqrt(0.5 / 1.4), 1e-12);
  // Two collinear halves: blended, the same time as one segment (no stop in the middle),
  // against two rest-to-rest halves at sqrt(2) times it.
  JointVector half = a;
  half[1] = 0.25;
  const Trajectory straight =
      Trajectory::blended({a, half, b}, arm.maxVelocity(), arm.maxAcceleration());
  EXPECT_TRUE(straight.isBlended());
  EXPECT_NEAR(straight.duration_s(), one.duration_s(), 1e-6);
  EXPECT_NEAR(Trajectory({a, half, b}, arm.maxVelocity(), arm.maxAcceleration()).duration_s(),
              std::sqrt(2.0) * one.duration_s(), 1e-9);
  EXPECT_LT(straight.maxCornerDeviation(), 1e-9);
  // A right-angle corner: faster than stopping, and the corner is cut.
  c[1] = 0.5, c[2] = 0.5;
  const Trajectory corner =
      Trajectory::blended({a, b, c}, arm.maxVelocity(), arm.maxAcceleration());
  EXPECT_TRUE(corner.isBlended());
  EXPECT_LT(corner.duration_s(),
            Trajectory({a, b, c}, arm.maxVelocity(), arm.maxAcceleration()).duration_s());
  EXPECT_GT(corner.maxCornerDeviation(), 0.0);
}

}  // namespace
// A rest at a via point: the arm passes it exactly, at rest, and each run between rests is
// blended as blended() times that run alone; no rests is blended(), every via point a rest
// is rest to rest. Limits as everywhere.
TEST(Trajectory, BlendedWithStopsRestsExactlyWhereToldAndBlendsTheRest) {
  const ArmModel arm{ArmConfig{}};
  const JointVector& v_max = arm.maxVelocity();
  const JointVector& a_max = arm.maxAcceleration();
  std::vector<JointVector> path(5, JointVector::Zero());
  path[1][1] = 0.5;
  path[2][1] = 0.5, path[2][2] = 0.5;
  path[3][2] = 0.5;
  path[4][2] = 0.5, path[4][3] = -0.6;
  const std::vector<bool> none(5, false), every(5, true);
  EXPECT_NEAR(Trajectory::blendedWithStops(path, none, v_max, a_max).duration_s(),
              Trajectory::blended(path, v_max, a_max).duration_s(), 1e-12);
  const Trajectory all = Trajectory::blendedWithStops(path, every, v_max, a_max);
  EXPECT_FALSE(all.isBlended());
  EXPECT_NEAR(all.duration_s(), Trajectory(path, v_max, a_max).duration_s(), 1e-12);

  std::vector<bool> at_two = none;
  at_two[2] = true;
  const Trajectory rests = Trajectory::blendedWithStops(path, at_two, v_max, a_max);
  EXPECT_TRUE(rests.isBlended());
  const double first_s =
      Trajectory::blended({path.begin(), path.begin() + 3}, v_max, a_max).duration_s();
  const double second_s =
      Trajectory::blended({path.begin() + 2, path.end()}, v_max, a_max).duration_s();
  EXPECT_NEAR(rests.duration_s(), first_s + second_s, 1e-12);
  EXPECT_LT((rests.position(first_s) - path[2]).norm(), 1e-9);  // on the via point,
  EXPECT_LT(rests.velocity(first_s).norm(), 1e-9);              // at rest
  // Slower than blending every corner, quicker than resting at every one.
  EXPECT_GT(rests.duration_s(), Trajectory::blended(path, v_max, a_max).duration_s());
  EXPECT_LT(rests.duration_s(), all.duration_s());
  for (int k = 0; k <= 2000; ++k) {
    const double t = rests.duration_s() * k / 2000;
    for (int j = 0; j < kArmJoints; ++j) {
      ASSERT_LE(std::abs(rests.velocity(t)[j]), v_max[j] * (1.0 + 1e-9)) << "t " << t;
      ASSERT_LE(std::abs(rests.acceleration(t)[j]), a_max[j] * (1.0 + 1e-9)) << "t " << t;
    }
  }
  EXPECT_THROW(Trajectory::blendedWithStops(path, {false, true}, v_max, a_max),
               std::invalid_argument);
}

}  // namespace fvp::robot
