// Workspace tree against direct IK on random camera poses around the tree: positions in the
// box the planner samples (around the cluster, on the robot's side), random viewing
// directions, image "down" towards world -z (as sim::lookAt and the planner make them).
#pragma once

#include <iostream>
#include <random>

#include "fvp/robot/arm_model.h"
#include "fvp/robot/sim/camera_views.h"
#include "fvp/robot/workspace_tree.h"

namespace fvp::robot::testing {

struct Agreement {
  int poses = 0, agree = 0, ik_reachable = 0, tree_only = 0, ik_only = 0;
  double rate() const { return poses == 0 ? 0.0 : static_cast<double>(agree) / poses; }
  void print(std::ostream& out, const WorkspaceTree& tree) const {
    out << "workspace tree (" << tree.resolution_m() << " m cells, " << tree.directionBins()
        << " direction bins, " << tree.nonEmptyBins() << " non-empty): agrees with IK on " << agree
        << "/" << poses << " poses (" << 100.0 * rate() << " %); IK reachable " << ik_reachable
        << "; tree yes / IK no " << tree_only << "; tree no / IK yes " << ik_only << "\n";
  }
};

inline Agreement compareWithIk(const ArmModel& arm, const WorkspaceTree& tree, int poses,
                               std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> x(-0.6, 0.6), y(-0.6, 0.2), z(0.7, 1.4), unit(-1.0, 1.0);
  Agreement a;
  for (int i = 0; i < poses; ++i) {
    const Eigen::Vector3d eye(x(rng), y(rng), z(rng));
    Eigen::Vector3d dir(unit(rng), unit(rng), unit(rng));
    if (dir.norm() < 1e-3) dir = Eigen::Vector3d::UnitY();
    const Eigen::Isometry3d T = sim::lookAt(eye, eye + dir.normalized());
    const bool by_ik = arm.reachableByIk(T), by_tree = tree.reachable(T);
    ++a.poses;
    a.agree += by_ik == by_tree ? 1 : 0;
    a.ik_reachable += by_ik ? 1 : 0;
    a.tree_only += by_tree && !by_ik ? 1 : 0;
    a.ik_only += by_ik && !by_tree ? 1 : 0;
  }
  return a;
}

}  // namespace fvp::robot::testing
