#include "fvp/robot/arm_collision_checker.h"

#include <octomap/OcTree.h>

#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include <fcl/geometry/octree/octree.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_request.h>
#include <fcl/narrowphase/collision_result.h>

#include "fvp/robot/occupancy_distance_field.h"

namespace fvp::robot {

struct ArmCollisionChecker::Fcl {
  std::shared_ptr<fcl::OcTreed> tree;
  // Occupied voxels' bounds: capsules whose box misses them skip the FCL traversal.
  Eigen::AlignedBox3d occupied_bounds;
  // With the field no capsule takes FCL's traversal: its bounds decide most, its exact test
  // over the nearby voxels the rest. FCL's traversal of a dense 1 cm tree map costs a link near
  // the canopy up to milliseconds (development season 1's first visit planned for 9 times
  // what the fixed clock charged). Empty with occupied voxels only when the grid would be too
  // large: then FCL decides every capsule.
  OccupancyDistanceField distance;
};

// Beyond FCL's GJK tolerance: the field's bounds decide only capsules this far from contact
// (FCL's answer for them is certain); its exact test decides the nearer ones.
constexpr double kFieldMarginM = 1e-3;

ArmCollisionChecker::ArmCollisionChecker(const ArmModel& arm) : arm_(arm) {}
ArmCollisionChecker::~ArmCollisionChecker() = default;

namespace {

// FCL's capsule for a link, padded, and its pose (FCL capsules lie along their local z axis).
std::pair<fcl::Capsuled, fcl::Transform3d> fclCapsule(const Capsule& link, double pad_m) {
  const Eigen::Vector3d axis = link.b_m - link.a_m;
  const double length = axis.norm();
  fcl::Capsuled capsule(link.radius_m + pad_m, length);
  capsule.computeLocalAABB();
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.translation() = 0.5 * (link.a_m + link.b_m);
  if (length > 1e-12) {
    tf.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis / length)
                      .toRotationMatrix();
  }
  return {capsule, tf};
}

Eigen::AlignedBox3d paddedBounds(const Capsule& link, double pad_m) {
  const double r = link.radius_m + pad_m;
  Eigen::AlignedBox3d box(link.a_m.cwiseMin(link.b_m), link.a_m.cwiseMax(link.b_m));
  box.min().array() -= r;
  box.max().array() += r;
  return box;
}

bool capsuleTouchesBox(const fcl::Capsuled& capsule, const fcl::Transform3d& tf,
                       const Eigen::Vector3d& centre_m, double size_m) {
  const fcl::Boxd box(size_m, size_m, size_m);
  fcl::Transform3d box_tf = fcl::Transform3d::Identity();
  box_tf.translation() = centre_m;
  fcl::CollisionRequestd request;
  fcl::CollisionResultd result;
  fcl::collide(&box, box_tf, &capsule, tf, request, result);
  return result.isCollision();
}

/// The distance field of the map's occupied voxels (pruned leaves larger than a voxel split into
/// voxels); empty when there are none, or when their bounds span more cells than the field
/// takes (the span is checked before any leaf is split).
OccupancyDistanceField distanceFieldOf(const octomap::OcTree& map,
                                       const Eigen::AlignedBox3d& occupied_bounds) {
  if (occupied_bounds.isEmpty()) return {};
  const double resolution = map.getResolution();
  const Eigen::Array3d span = (occupied_bounds.sizes() / resolution).array().round();
  if (span.prod() > static_cast<double>(OccupancyDistanceField::kDefaultMaxCells)) return {};
  std::vector<Eigen::Vector3i> voxels;
  for (auto it = map.begin_leafs(), end = map.end_leafs(); it != end; ++it) {
    if (!map.isNodeOccupied(*it)) continue;
    const double half = 0.5 * it.getSize();
    const Eigen::Vector3d c(it.getX(), it.getY(), it.getZ());
    const int cells = static_cast<int>(std::lround(it.getSize() / resolution));
    const Eigen::Vector3i first =
        ((c.array() - half) / resolution + 0.5).floor().cast<int>().matrix();
    for (int i = 0; i < cells; ++i)
      for (int j = 0; j < cells; ++j)
        for (int k = 0; k < cells; ++k) voxels.push_back(first + Eigen::Vector3i(i, j, k));
  }
  try {
    return OccupancyDistanceField(resolution, voxels);
  } catch (const std::invalid_argument&) {
    return {};  // too large a grid: FCL decides every capsule near the occupied bounds
  }
}

}  // namespace

void ArmCollisionChecker::setMap(const octomap::OcTree& coarse_map) {
  setMapOwned(std::make_shared<octomap::OcTree>(coarse_map));
}

std::size_t ArmCollisionChecker::setMapFreeAt(const octomap::OcTree& coarse_map,
                                              const JointVector& q_now) {
  auto copy = std::make_shared<octomap::OcTree>(coarse_map);
  const double pad = arm_.config().collision_padding_m;
  std::vector<std::pair<fcl::Capsuled, fcl::Transform3d>> capsules;
  std::vector<Eigen::AlignedBox3d> capsule_bounds;
  for (const Capsule& link : arm_.linkCapsules(q_now)) {
    capsules.push_back(fclCapsule(link, pad));
    capsule_bounds.push_back(paddedBounds(link, pad));
  }
  const auto touched = [&](const Eigen::Vector3d& centre_m, double size_m) {
    const Eigen::Vector3d half = Eigen::Vector3d::Constant(0.5 * size_m);
    const Eigen::AlignedBox3d box(centre_m - half, centre_m + half);
    for (std::size_t i = 0; i < capsules.size(); ++i) {
      if (box.intersects(capsule_bounds[i]) &&
          capsuleTouchesBox(capsules[i].first, capsules[i].second, centre_m, size_m))
        return true;
    }
    return false;
  };
  // Collect first (the tree must not change under its iterator). A pruned leaf larger than
  // one voxel is split: only the voxels of it that the arm overlaps are freed.
  std::vector<octomap::OcTreeKey> to_free;
  const double resolution = copy->getResolution();
  for (auto it = copy->begin_leafs(), end = copy->end_leafs(); it != end; ++it) {
    if (!copy->isNodeOccupied(*it)) continue;
    const Eigen::Vector3d centre(it.getX(), it.getY(), it.getZ());
    if (!touched(centre, it.getSize())) continue;
    const int cells = static_cast<int>(std::lround(it.getSize() / resolution));
    const Eigen::Vector3d first =
        centre - Eigen::Vector3d::Constant(0.5 * (cells - 1) * resolution);
    for (int i = 0; i < cells; ++i)
      for (int j = 0; j < cells; ++j)
        for (int k = 0; k < cells; ++k) {
          const Eigen::Vector3d v = first + resolution * Eigen::Vector3d(i, j, k);
          if (cells == 1 || touched(v, resolution))
            to_free.push_back(copy->coordToKey(v.x(), v.y(), v.z()));
        }
  }
  for (const octomap::OcTreeKey& key : to_free)
    copy->setNodeValue(key, copy->getClampingThresMinLog(), /*lazy_eval=*/true);
  if (!to_free.empty()) copy->updateInnerOccupancy();
  setMapOwned(std::move(copy));
  return to_free.size();
}

void ArmCollisionChecker::setMapOwned(std::shared_ptr<octomap::OcTree> copy) {
  auto fcl = std::make_unique<Fcl>();
  fcl->occupied_bounds.setEmpty();
  // The bounds' and the field's voxels: OctoMap's occupied test, FCL's too (log-odds at or
  // above the threshold), so that both judge exactly the voxels FCL would test.
  for (auto it = copy->begin_leafs(), end = copy->end_leafs(); it != end; ++it) {
    if (!copy->isNodeOccupied(*it)) continue;
    const Eigen::Vector3d c(it.getX(), it.getY(), it.getZ());
    fcl->occupied_bounds.extend(c - Eigen::Vector3d::Constant(0.5 * it.getSize()));
    fcl->occupied_bounds.extend(c + Eigen::Vector3d::Constant(0.5 * it.getSize()));
  }
  fcl->distance = distanceFieldOf(*copy, fcl->occupied_bounds);
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
  return mapCollision_(links, use_distance_field_);
}

bool ArmCollisionChecker::mapCollisionFclOnly(const LinkCapsules& links) const {
  return mapCollision_(links, /*use_field=*/false);
}

bool ArmCollisionChecker::mapCollision_(const LinkCapsules& links, bool use_field) const {
  if (!fcl_ || fcl_->occupied_bounds.isEmpty()) return false;
  const double pad = arm_.config().collision_padding_m;
  use_field = use_field && !fcl_->distance.empty();
  for (const Capsule& link : links) {
    // A link that is not numbers is nowhere a plan may put it (the bounds would skip it).
    if (!link.a_m.allFinite() || !link.b_m.allFinite() || !std::isfinite(link.radius_m))
      return true;
    if (!paddedBounds(link, pad).intersects(fcl_->occupied_bounds)) continue;
    if (use_field) {
      using Verdict = OccupancyDistanceField::CapsuleVerdict;
      const Verdict verdict =
          fcl_->distance.capsuleVerdict(link.a_m, link.b_m, link.radius_m + pad, kFieldMarginM);
      if (verdict == Verdict::kClear) continue;
      if (verdict == Verdict::kTouching) return true;
      if (fcl_->distance.capsuleTouches(link.a_m, link.b_m, link.radius_m + pad)) return true;
      continue;
    }
    const auto [capsule, tf] = fclCapsule(link, pad);
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
