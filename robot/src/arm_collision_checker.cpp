#include "fvp/robot/arm_collision_checker.h"

#include <octomap/OcTree.h>

#include <fcl/geometry/octree/octree.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_request.h>
#include <fcl/narrowphase/collision_result.h>

namespace fvp::robot {

struct ArmCollisionChecker::Fcl {
  std::shared_ptr<fcl::OcTreed> tree;
  // Occupied voxels' bounds: capsules whose box misses them skip the FCL traversal.
  Eigen::AlignedBox3d occupied_bounds;
};

ArmCollisionChecker::ArmCollisionChecker(const ArmModel& arm) : arm_(arm) {}
ArmCollisionChecker::~ArmCollisionChecker() = default;

void ArmCollisionChecker::setMap(const octomap::OcTree& coarse_map) {
  auto copy = std::make_shared<octomap::OcTree>(coarse_map);
  auto fcl = std::make_unique<Fcl>();
  fcl->occupied_bounds.setEmpty();
  for (auto it = copy->begin_leafs(), end = copy->end_leafs(); it != end; ++it) {
    if (!copy->isNodeOccupied(*it)) continue;
    const double half = 0.5 * it.getSize();
    const Eigen::Vector3d c(it.getX(), it.getY(), it.getZ());
    fcl->occupied_bounds.extend(c - Eigen::Vector3d::Constant(half));
    fcl->occupied_bounds.extend(c + Eigen::Vector3d::Constant(half));
  }
  fcl->tree = std::make_shared<fcl::OcTreed>(std::shared_ptr<const octomap::OcTree>(copy));
  // Subtrees whose largest log-odds is below the occupancy threshold hold no obstacle:
  // let FCL prune them (inner nodes carry their children's maximum).
  fcl->tree->setFreeThres(copy->getOccupancyThres() - 1e-6);
  fcl->tree->computeLocalAABB();
  fcl_ = std::move(fcl);
}

void ArmCollisionChecker::clearMap() {
  fcl_.reset();
}
bool ArmCollisionChecker::hasMap() const {
  return fcl_ != nullptr;
}

bool ArmCollisionChecker::mapCollision(const LinkCapsules& links) const {
  if (!fcl_ || fcl_->occupied_bounds.isEmpty()) return false;
  const double pad = arm_.config().collision_padding_m;
  for (const Capsule& link : links) {
    const double r = link.radius_m + pad;
    Eigen::AlignedBox3d box(link.a_m.cwiseMin(link.b_m), link.a_m.cwiseMax(link.b_m));
    box.min().array() -= r;
    box.max().array() += r;
    if (!box.intersects(fcl_->occupied_bounds)) continue;
    const Eigen::Vector3d axis = link.b_m - link.a_m;
    const double length = axis.norm();
    fcl::Capsuled capsule(r, length);
    capsule.computeLocalAABB();
    fcl::Transform3d tf = fcl::Transform3d::Identity();
    tf.translation() = 0.5 * (link.a_m + link.b_m);
    if (length > 1e-12) {
      tf.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis / length)
                        .toRotationMatrix();
    }
    fcl::CollisionRequestd request;  // one contact is enough
    fcl::CollisionResultd result;
    fcl::collide(fcl_->tree.get(), fcl::Transform3d::Identity(), &capsule, tf, request, result);
    if (result.isCollision()) return true;
  }
  return false;
}

bool ArmCollisionChecker::isValid(const JointVector& q) const {
  checks_.fetch_add(1, std::memory_order_relaxed);
  if (!arm_.withinLimits(q)) return false;
  const LinkCapsules links = arm_.linkCapsules(q);
  return !arm_.selfOrStaticCollision(links) && !mapCollision(links);
}

}  // namespace fvp::robot
