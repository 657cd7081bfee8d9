// Whether an arm configuration is valid: within joint limits, free of self collision, the
// ground and the slider rail, and with no link capsule (padded by collision_padding_m)
// touching an occupied voxel of the coarse map. The map check is a distance field over the
// occupied voxels (OccupancyDistanceField): its bounds, and an exact capsule-against-voxel test
// where they cannot tell. FCL's capsule-against-fcl::OcTree test over a copy of the
// octomap::OcTree, as MoveIt does it, is the oracle it is tested against (the same answers but
// within a micrometre of contact, FCL's GJK tolerance, where the exact test's is right), the
// benchmarks' peer, and the check when the occupied voxels span too large a grid for a field.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "fvp/robot/arm_model.h"

namespace octomap {
class OcTree;
}

namespace fvp::robot {

class ArmCollisionChecker {
 public:
  /// `arm` must outlive the checker. No map: only limits, self and static checks apply.
  explicit ArmCollisionChecker(const ArmModel& arm);
  ~ArmCollisionChecker();
  ArmCollisionChecker(const ArmCollisionChecker&) = delete;
  ArmCollisionChecker& operator=(const ArmCollisionChecker&) = delete;

  /// Copies the coarse map (MapEngine::coarseOcTree()); voxels with occupancy above the
  /// tree's threshold are obstacles, unknown space is not.
  void setMap(const octomap::OcTree& coarse_map);
  /// setMap, with the occupied voxels that the arm's padded links overlap at configuration
  /// `q_now` taken as free: the arm is physically there, so what the map holds there is
  /// stereo noise or a surface the padding grazes, not an obstacle. MoveIt's octomap
  /// updaters filter the points around the robot's links out likewise (its tutorials'
  /// configurations pad the links by 10 cm; ours is the 1 cm collision padding). Without this, one
  /// such voxel makes every plan from `q_now` fail as start_invalid. The cost: a real obstacle
  /// within the padding of where the arm stands is not avoided by the next motion. Returns how many
  /// finest-level voxels were freed.
  std::size_t setMapFreeAt(const octomap::OcTree& coarse_map, const JointVector& q_now);
  void clearMap();
  bool hasMap() const;

  bool isValid(const JointVector& q) const;
  /// Only the map part of isValid, for given capsules (padding is added here).
  bool mapCollision(const LinkCapsules& links) const;
  /// mapCollision by FCL alone, every capsule near the occupied voxels traversed: the oracle
  /// the distance field's checks are tested and measured against.
  bool mapCollisionFclOnly(const LinkCapsules& links) const;
  /// Whether isValid and mapCollision use the distance field (default true; false: FCL alone,
  /// the same answers but within a micrometre of contact, more slowly, for benchmarks).
  void setUseDistanceField(bool use) { use_distance_field_ = use; }
  const ArmModel& arm() const { return arm_; }
  /// isValid calls so far (planning statistics).
  std::uint64_t checks() const { return checks_.load(std::memory_order_relaxed); }

 private:
  struct Fcl;
  void setMapOwned(std::shared_ptr<octomap::OcTree> map);
  bool mapCollision_(const LinkCapsules& links, bool use_field) const;
  const ArmModel& arm_;
  std::unique_ptr<Fcl> fcl_;
  mutable std::atomic<std::uint64_t> checks_{0};
  bool use_distance_field_ = true;
};

}  // namespace fvp::robot
