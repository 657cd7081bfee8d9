// Forward/inverse kinematics of the UR5 and the slider-mounted arm.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <random>

#include "fvp/robot/arm_model.h"
#include "fvp/robot/sim/arm_controller.h"
#include "fvp/robot/sim/camera_views.h"
#include "fvp/robot/sim/sim_clock.h"
#include "fvp/robot/sim/world.h"
#include "fvp/robot/ur5_kinematics.h"

namespace fvp::robot {
namespace {
using sim::ArmController;

double rotationError(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

TEST(Ur5Kinematics, RoundTripOnRandomConfigurations) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(-2.0 * std::numbers::pi, 2.0 * std::numbers::pi);
  int solutions = 0, original_found = 0;
  double max_position = 0.0, max_rotation = 0.0;
  constexpr int kConfigurations = 10000;
  for (int i = 0; i < kConfigurations; ++i) {
    Ur5Kinematics::Joints q;
    for (int j = 0; j < 6; ++j) q[j] = angle(rng);
    const Eigen::Isometry3d T = Ur5Kinematics::forward(q);
    std::array<Ur5Kinematics::Joints, Ur5Kinematics::kMaxSolutions> ik;
    const int n = Ur5Kinematics::inverse(T, ik);
    ASSERT_GT(n, 0) << "configuration " << i;
    bool found = false;
    for (int k = 0; k < n; ++k) {
      const Eigen::Isometry3d T_k = Ur5Kinematics::forward(ik[k]);
      max_position = std::max(max_position, (T_k.translation() - T.translation()).norm());
      max_rotation = std::max(max_rotation, rotationError(T_k.linear(), T.linear()));
      // Every returned angle is in (-pi, pi].
      EXPECT_TRUE((ik[k].array().abs() <= std::numbers::pi + 1e-12).all());
      Ur5Kinematics::Joints diff = ik[k] - q;
      for (int j = 0; j < 6; ++j) diff[j] = std::remainder(diff[j], 2.0 * std::numbers::pi);
      found = found || diff.cwiseAbs().maxCoeff() < 1e-6;
    }
    solutions += n;
    original_found += found ? 1 : 0;
  }
  EXPECT_LT(max_position, 1e-6);
  EXPECT_LT(max_rotation, 1e-6);
  // The configuration we started from is among the solutions (up to 2 pi) almost always;
  // near-singular wrists (sin q5 ~ 0) are the exception.
  EXPECT_GE(original_found, kConfigurations * 999 / 1000);
  std::cout << "IK: " << solutions << " solutions for " << kConfigurations
            << " poses; max position error " << max_position << " m, rotation " << max_rotation
            << " rad; original among them for " << original_found << "\n";
}

TEST(Ur5Kinematics, UnreachablePosesHaveNoSolution) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < 1000; ++i) {
    Eigen::Vector3d dir(unit(rng), unit(rng), unit(rng));
    dir.normalize();
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
    T.translation() = (1.2 + 0.5 * std::abs(unit(rng))) * dir;  // beyond the 1.03 m reach
    std::array<Ur5Kinematics::Joints, Ur5Kinematics::kMaxSolutions> ik;
    EXPECT_EQ(Ur5Kinematics::inverse(T, ik), 0);
  }
}

TEST(ArmModel, SweepBoundCoversEveryCapsulePoint) {
  // Motion checks rely on sweepBound_m: no capsule point moves farther than it. A capsule's
  // points move at most as far as its farthest end point plus its radius times the link's
  // rotation, itself at most the sum of the revolute joints' angles.
  const ArmModel arm{ArmConfig{}};
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> unit(0.0, 1.0), small(-0.05, 0.05);
  double tightest = 0.0;
  for (int i = 0; i < 5000; ++i) {
    JointVector q, dq;
    for (int j = 0; j < kArmJoints; ++j) {
      q[j] = arm.lowerLimits()[j] + unit(rng) * (arm.upperLimits()[j] - arm.lowerLimits()[j]);
      dq[j] = unit(rng) < 0.3 ? 0.0 : small(rng);  // some joints still, as on real motions
    }
    const LinkCapsules before = arm.linkCapsules(q), after = arm.linkCapsules(q + dq);
    const double rotation = dq.tail<6>().cwiseAbs().sum();
    const double bound = arm.sweepBound_m(dq);
    for (std::size_t k = 0; k < before.size(); ++k) {
      const double moved =
          std::max((after[k].a_m - before[k].a_m).norm(), (after[k].b_m - before[k].b_m).norm()) +
          before[k].radius_m * rotation;
      // A slider-only motion moves every point by exactly the bound: allow rounding.
      ASSERT_LE(moved, bound * (1.0 + 1e-9)) << "capsule " << k << ", configuration " << i;
      tightest = std::max(tightest, moved / bound);
    }
  }
  std::cout << "largest capsule sweep / bound: " << tightest << "\n";
}

TEST(ArmModel, RoundTripWithSliderAndLimits) {
  const ArmModel arm{ArmConfig{}};
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int checked = 0;
  for (int i = 0; i < 2000; ++i) {
    JointVector q;
    for (int j = 0; j < kArmJoints; ++j)
      q[j] = arm.lowerLimits()[j] + unit(rng) * (arm.upperLimits()[j] - arm.lowerLimits()[j]);
    const Eigen::Isometry3d T = arm.T_world_camera(q);
    std::vector<JointVector> solutions;
    arm.inverseAt(T, q[0], q, solutions);
    ASSERT_FALSE(solutions.empty());
    bool original = false;
    for (const JointVector& s : solutions) {
      EXPECT_TRUE(arm.withinLimits(s));
      const Eigen::Isometry3d T_s = arm.T_world_camera(s);
      EXPECT_LT((T_s.translation() - T.translation()).norm(), 1e-6);
      EXPECT_LT(rotationError(T_s.linear(), T.linear()), 1e-6);
      original = original || (s - q).cwiseAbs().maxCoeff() < 1e-6;
      ++checked;
    }
    // Solutions are expressed in the 2 pi branch nearest the reference: q itself is one.
    EXPECT_TRUE(original || std::abs(std::sin(q[5])) < 1e-3) << "configuration " << i;
  }
  EXPECT_GT(checked, 2000);
}

TEST(ArmModel, InverseAlongTravelIsSortedAndOnlyWithinTravel) {
  const ArmModel arm{ArmConfig{}};
  const JointVector home = arm.homeConfiguration();
  const Eigen::Isometry3d T = arm.T_world_camera(home);
  const auto solutions = arm.inverse(T, home);
  ASSERT_FALSE(solutions.empty());
  EXPECT_LT((solutions.front() - home).norm(), 1e-6);  // the current configuration first
  // Soonest reached first (the slowest joint's time), the joint distance breaking ties.
  for (std::size_t i = 1; i < solutions.size(); ++i) {
    const double before_s = arm.travelTime_s(home, solutions[i - 1]);
    const double after_s = arm.travelTime_s(home, solutions[i]);
    EXPECT_LE(before_s, after_s);
    if (before_s == after_s) {
      EXPECT_LE(jointDistance(solutions[i - 1], home), jointDistance(solutions[i], home));
    }
    EXPECT_TRUE(arm.withinLimits(solutions[i]));
  }
  // The order is the time's, not the distance's: a pose whose solutions the two rank apart.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> angle(-1.5, 1.5);
  int ranked_apart = 0;
  for (int trial = 0; trial < 200 && ranked_apart == 0; ++trial) {
    JointVector q = home;
    for (int j = 1; j < kArmJoints; ++j) q[j] += angle(rng);
    if (!arm.withinLimits(q)) continue;
    const auto all = arm.inverse(arm.T_world_camera(q), home);
    const auto by_distance =
        std::min_element(all.begin(), all.end(), [&](const auto& a, const auto& b) {
          return jointDistance(a, home) < jointDistance(b, home);
        });
    if (!all.empty() && arm.travelTime_s(home, *by_distance) > arm.travelTime_s(home, all.front()))
      ++ranked_apart;
  }
  EXPECT_GT(ranked_apart, 0);
  // Far beyond the slider's reach: nothing.
  Eigen::Isometry3d far = T;
  far.translation().x() += 5.0;
  EXPECT_TRUE(arm.inverse(far, home).empty());
}

TEST(ArmModel, HomeIsFreeAndLinksHaveSaneGeometry) {
  const ArmModel arm{ArmConfig{}};
  const JointVector home = arm.homeConfiguration();
  EXPECT_TRUE(arm.withinLimits(home));
  EXPECT_FALSE(arm.selfOrStaticCollision(arm.linkCapsules(home)));
  // Elbow folded back onto the upper arm: self collision.
  JointVector folded = home;
  folded[3] = std::numbers::pi - 0.05;
  EXPECT_TRUE(arm.selfOrStaticCollision(arm.linkCapsules(folded)));
  // Pointing the arm into the ground.
  JointVector down = home;
  down[2] = 0.5 * std::numbers::pi;
  down[3] = 0.0;
  EXPECT_TRUE(arm.selfOrStaticCollision(arm.linkCapsules(down)));
}

// The robot's placement: every generated world's start view is reachable (its IK gives the
// start configuration) and so are views around it, with room to spare.
TEST(ArmModel, StartViewsOfGeneratedWorldsAreWellInsideReach) {
  const ArmModel arm{ArmConfig{}};
  int orbit_total = 0, orbit_reached = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const auto world = sim::World::generate(sim::WorldConfig{}, seed);
    const auto start = ArmController::startConfiguration(arm, world.startCameraPose());
    ASSERT_TRUE(start.has_value()) << "seed " << seed;
    EXPECT_LT(
        (arm.T_world_camera(*start).translation() - world.startCameraPose().translation()).norm(),
        1e-6);
    // Well inside: the same view from 10 cm farther and 10 cm nearer, 10 cm higher and lower.
    const Eigen::Isometry3d T0 = world.startCameraPose();
    const Eigen::Vector3d back = -T0.linear().col(2);
    for (const Eigen::Vector3d& shift : {Eigen::Vector3d(0.1 * back), Eigen::Vector3d(-0.1 * back),
                                         Eigen::Vector3d(0, 0, 0.1), Eigen::Vector3d(0, 0, -0.1)}) {
      Eigen::Isometry3d T = T0;
      T.translation() += shift;
      EXPECT_TRUE(arm.reachableByIk(T)) << "seed " << seed << " shift " << shift.transpose();
    }
    for (const auto& T : sim::orbitViews(world, 5, 120.0)) {
      ++orbit_total;
      const bool ok = arm.reachableByIk(T);
      orbit_reached += ok ? 1 : 0;
      if (!ok)
        std::cout << "seed " << seed << ": orbit view at " << T.translation().transpose()
                  << " looking " << T.linear().col(2).transpose() << " unreachable; ik "
                  << arm.inverse(T, arm.homeConfiguration()).size() << "\n";
    }
  }
  EXPECT_EQ(orbit_reached, orbit_total);
}

}  // namespace
}  // namespace fvp::robot

namespace fvp::robot {
namespace {

// Trees: every cluster's start view is reachable, and in an empty world the arm moves from
// the first cluster's start view to every other's.
TEST(ArmModel, EveryClusterOfATreeIsReachedFromTheFirst) {
  const ArmModel arm{ArmConfig{}};
  sim::WorldConfig config;
  config.cluster_count = 4;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const auto world = sim::World::generate(config, seed);
    for (const auto& cluster : world.clusters()) {
      const auto start = ArmController::startConfiguration(arm, cluster.T_world_start_camera);
      ASSERT_TRUE(start.has_value()) << "seed " << seed << " cluster " << cluster.index;
      sim::SimClock clock(sim::SimClock::Mode::kFixed);
      ArmController controller(arm, clock,
                               *ArmController::startConfiguration(arm, world.startCameraPose()));
      controller.setReproducibleMotionPlanning(seed);
      const MotionPlan plan = controller.moveToPose(cluster.T_world_start_camera);
      EXPECT_EQ(plan.status, MotionStatus::kSuccess)
          << "seed " << seed << " cluster " << cluster.index;
    }
  }
}

}  // namespace
}  // namespace fvp::robot
