#include "fvp/robot/sim/world_occupancy.h"

#include <cmath>
#include <numbers>

namespace fvp::robot::sim {
namespace {

constexpr double kPi = std::numbers::pi;

class Marker {
 public:
  Marker(octomap::OcTree& tree, const Eigen::AlignedBox3d& bounds, double step_m)
      : tree_(tree), bounds_(bounds), step_(step_m) {}
  double step() const { return step_; }
  void mark(const Eigen::Vector3d& p) {
    if (!bounds_.contains(p)) return;
    octomap::OcTreeKey key;
    if (!tree_.coordToKeyChecked(p.x(), p.y(), p.z(), key)) return;
    if (tree_.search(key) == nullptr) tree_.updateNode(key, true, /*lazy_eval=*/true);
  }

 private:
  octomap::OcTree& tree_;
  Eigen::AlignedBox3d bounds_;
  double step_;
};

int stepsFor(double length_m, double step_m) {
  return std::max(1, static_cast<int>(std::ceil(length_m / step_m)));
}

void markCylinder(Marker& m, const BranchSegment& b) {
  const Eigen::Vector3d axis = b.end_m - b.start_m;
  const double length = axis.norm();
  const Eigen::Vector3d dir = axis / length;
  const Eigen::Vector3d u = dir.unitOrthogonal(), v = dir.cross(u);
  const int na = stepsFor(length + 2.0 * b.radius_m, m.step());
  const int nc = stepsFor(2.0 * kPi * b.radius_m, m.step());
  for (int i = 0; i <= na; ++i) {
    // Along the axis from one cap's tip to the other's: hemispherical caps.
    const double t = -b.radius_m + (length + 2.0 * b.radius_m) * i / na;
    const double beyond = t < 0.0 ? -t : (t > length ? t - length : 0.0);
    const double ring = std::sqrt(std::max(0.0, b.radius_m * b.radius_m - beyond * beyond));
    for (int k = 0; k < nc; ++k) {
      const double phi = 2.0 * kPi * k / nc;
      m.mark(b.start_m + t * dir + ring * (std::cos(phi) * u + std::sin(phi) * v));
    }
  }
}

void markLeaf(Marker& m, const Leaf& leaf) {
  const int nx = stepsFor(2.0 * leaf.half_length_m, m.step());
  const int ny = stepsFor(2.0 * leaf.half_width_m, m.step());
  for (int i = 0; i <= nx; ++i) {
    const double x = -leaf.half_length_m + 2.0 * leaf.half_length_m * i / nx;
    for (int j = 0; j <= ny; ++j) {
      const double y = -leaf.half_width_m + 2.0 * leaf.half_width_m * j / ny;
      const double e = (x * x) / (leaf.half_length_m * leaf.half_length_m) +
                       (y * y) / (leaf.half_width_m * leaf.half_width_m);
      if (e > 1.0) continue;
      m.mark(leaf.T_world_leaf * Eigen::Vector3d(x, y, leaf.curl_per_m * x * x));
    }
  }
}

void markEllipsoid(Marker& m, const Fruitlet& f) {
  const Eigen::Vector3d axes = f.semiAxes_m();
  const int n = stepsFor(kPi * axes.maxCoeff(), m.step());
  for (int i = 0; i <= n; ++i) {
    const double theta = kPi * i / n;
    for (int k = 0; k < 2 * n; ++k) {
      const double phi = kPi * k / n;
      const Eigen::Vector3d unit(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                                 std::cos(theta));
      m.mark(f.center_m + f.R_world_fruitlet * unit.cwiseProduct(axes));
    }
  }
}

void markPlate(Marker& m, const AprilTagPlacement& tag) {
  const double half = 0.5 * tag.plate_size_m;
  const int n = stepsFor(tag.plate_size_m, m.step());
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      m.mark(tag.T_world_tag * Eigen::Vector3d(-half + tag.plate_size_m * i / n,
                                               -half + tag.plate_size_m * j / n, 0));
    }
  }
}

}  // namespace

std::unique_ptr<octomap::OcTree> worldOccupancy(const World& world, double resolution_m,
                                                const Eigen::AlignedBox3d& bounds) {
  auto tree = std::make_unique<octomap::OcTree>(resolution_m);
  // A third of a voxel between samples, so hardly any voxel a surface crosses is missed.
  Marker marker(*tree, bounds, resolution_m / 3.0);
  for (const BranchSegment& b : world.branches()) markCylinder(marker, b);
  for (const Leaf& leaf : world.leaves()) markLeaf(marker, leaf);
  for (const Fruitlet& f : world.fruitlets()) markEllipsoid(marker, f);
  if (world.hasTag()) markPlate(marker, world.tag());
  tree->updateInnerOccupancy();
  return tree;
}

}  // namespace fvp::robot::sim
