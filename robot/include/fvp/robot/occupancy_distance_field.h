// Distances to the nearest occupied voxel of a map, as lower bounds that a collision check can
// trust: exact squared Euclidean distances between voxel centres (the separable transform of
// Felzenszwalb and Huttenlocher, "Distance Transforms of Sampled Functions", 2012) over the
// occupied voxels' bounding grid. The arm's collision check decides a capsule with it when every
// obstacle is clearly beyond the capsule's radius, or one clearly within it, and the rest by an
// exact capsule-against-voxel test over the occupied voxels near the capsule (bucketed in
// bricks), not FCL's octree traversal.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace fvp::robot {

class OccupancyDistanceField {
 public:
  /// No occupied voxel: every point is clear.
  OccupancyDistanceField() = default;
  /// Voxels of edge `voxel_size_m`; voxel index i spans [i, i + 1) * voxel_size_m on each axis
  /// (OctoMap's key minus its centre key). Throws std::invalid_argument when the voxels'
  /// bounding grid would hold more than `max_cells` cells.
  OccupancyDistanceField(double voxel_size_m, const std::vector<Eigen::Vector3i>& occupied,
                         std::size_t max_cells = kDefaultMaxCells);

  /// At most this many cells by default (4 bytes each): a 2 m cube at 1 cm is 8 M.
  static constexpr std::size_t kDefaultMaxCells = std::size_t{64} << 20;

  bool empty() const { return squared_distance_vox_.empty(); }
  double voxel_size_m() const { return voxel_size_m_; }
  Eigen::Vector3i gridMin() const { return min_; }
  Eigen::Vector3i gridSize() const { return size_; }

  /// Squared distance, in voxels, from voxel `index`'s centre to the nearest occupied voxel's
  /// centre; `index` must lie in the grid (checked twin: squaredDistanceVoxChecked).
  float squaredDistanceVox(const Eigen::Vector3i& index) const {
    return squared_distance_vox_[offsetOf(index - min_)];
  }
  /// squaredDistanceVox, or -1 when `index` lies outside the grid.
  float squaredDistanceVoxChecked(const Eigen::Vector3i& index) const;

  /// A lower bound on the distance from `point_m` to every occupied voxel's box (infinite
  /// when there is none; may be negative near one).
  double lowerBoundDistance_m(const Eigen::Vector3d& point_m) const;
  /// An upper bound on the distance from `point_m` to the nearest occupied voxel's box (its
  /// centre's distance); infinite outside the grid or with no occupied voxel.
  double upperBoundDistance_m(const Eigen::Vector3d& point_m) const;

  enum class CapsuleVerdict {
    kClear,      ///< more than the margin from every occupied voxel's box
    kTouching,   ///< more than the margin into an occupied voxel's box
    kUndecided,  ///< the bounds cannot tell: an exact test must
  };
  /// The capsule of segment a-b and `radius_m` against the occupied voxels, by the bounds.
  CapsuleVerdict capsuleVerdict(const Eigen::Vector3d& a_m, const Eigen::Vector3d& b_m,
                                double radius_m, double margin_m) const;
  /// Exactly whether the capsule of segment a-b and `radius_m` meets an occupied voxel's box
  /// (their distance at most the radius); true for inputs that are not numbers or lie
  /// kMaxCoordinateM or farther out (no arm's link).
  bool capsuleTouches(const Eigen::Vector3d& a_m, const Eigen::Vector3d& b_m,
                      double radius_m) const;

  /// Cells a brick spans along each axis: the exact test's buckets of occupied voxels.
  static constexpr int kBrickCells = 4;
  /// Coordinates and radii at or beyond this are no arm's: capsuleVerdict leaves them
  /// undecided, capsuleTouches answers touching.
  static constexpr double kMaxCoordinateM = 1e6;

 private:
  /// The storage offset of a cell at `local` from the grid's first cell (x fastest).
  std::size_t offsetOf(const Eigen::Vector3i& local) const {
    return static_cast<std::size_t>(local.x()) +
           static_cast<std::size_t>(size_.x()) *
               (static_cast<std::size_t>(local.y()) +
                static_cast<std::size_t>(size_.y()) * static_cast<std::size_t>(local.z()));
  }
  /// The offset of brick `brick` (bricks of kBrickCells cells from the grid's first) in the
  /// brick table (x fastest).
  std::size_t brickOffsetOf(const Eigen::Vector3i& brick) const {
    return static_cast<std::size_t>(brick.x()) +
           static_cast<std::size_t>(bricks_.x()) *
               (static_cast<std::size_t>(brick.y()) +
                static_cast<std::size_t>(bricks_.y()) * static_cast<std::size_t>(brick.z()));
  }
  /// The grid cell holding `point_m`, false outside the grid.
  bool cellOf(const Eigen::Vector3d& point_m, Eigen::Vector3i& index) const;
  /// Buckets the occupied voxels by brick (brick_first_, brick_voxels_).
  void bucketByBrick(const std::vector<Eigen::Vector3i>& occupied);
  /// capsuleTouches over the part a-b of the axis, clipped to near the grid: halved while the
  /// bounds cannot clear a part longer than a brick and the radius.
  bool touchesAlong(const Eigen::Vector3d& a_m, const Eigen::Vector3d& b_m, double radius_m) const;
  /// capsuleTouches by testing every occupied voxel of the bricks near the segment a-b.
  bool touchesInBricks(const Eigen::Vector3d& a_m, const Eigen::Vector3d& b_m,
                       double radius_m) const;
  double voxel_size_m_ = 0.0;
  Eigen::Vector3i min_ = Eigen::Vector3i::Zero();
  Eigen::Vector3i size_ = Eigen::Vector3i::Zero();
  std::vector<float> squared_distance_vox_;
  Eigen::Vector3i bricks_ = Eigen::Vector3i::Zero();  ///< bricks along each axis
  /// Brick b's occupied voxels are brick_voxels_[brick_first_[b] .. brick_first_[b + 1]).
  std::vector<std::uint32_t> brick_first_;
  std::vector<Eigen::Vector3i> brick_voxels_;
};

}  // namespace fvp::robot
