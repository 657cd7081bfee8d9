// Robust sphere fitting for the sizing chain, and the split of DBSCAN clusters that hold
// more than one fruitlet.
//
// DBSCAN over surface points separates fruitlets whose surfaces are farther apart than its
// eps. Two that nearly touch (world 4 of the unoccluded set: 4.6 mm apart, with stereo
// points at the depth edges between them) come out as one cluster, and then neither is
// matched: the cluster's centre lies between them. A fruitlet is close to a sphere, so a
// cluster holding two is one sphere's points plus another's: sequential RANSAC finds the
// larger, then the larger among the points it leaves, while each new sphere is a fruitlet of
// its own (enough points, its centre outside the others' spheres). A single
// elongated fruitlet's ends lie within a millimetre of its best sphere, and stay whole.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace fvp::host::sizing {

inline constexpr double kDefaultSphereInlierTolerance_m = 0.0005;
inline constexpr double kDefaultMinFruitletRadius_m = 0.0015;
inline constexpr double kDefaultMaxFruitletRadius_m = 0.012;

struct SphereRansacConfig {
  /// A point is an inlier when its distance to the sphere is at most this.
  double inlier_tolerance_m = kDefaultSphereInlierTolerance_m;
  /// Hypotheses outside this radius range are rejected (a fruitlet's, with margin).
  double min_radius_m = kDefaultMinFruitletRadius_m;
  double max_radius_m = kDefaultMaxFruitletRadius_m;
  int iterations = 256;
  std::uint64_t seed = 1;  ///< fixed: the same points give the same sphere
  void validate() const;
};

struct SphereFit {
  bool found = false;
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
  std::vector<std::size_t> inliers;  ///< indices into the points, ascending
  double inlierFraction(std::size_t point_count) const {
    return point_count ? double(inliers.size()) / double(point_count) : 0.0;
  }
};

/// Least-squares sphere through points (algebraic fit); false when degenerate.
bool fitSphere(const std::vector<Eigen::Vector3f>& points, Eigen::Vector3d& center_m,
               double& radius_m);

/// The sphere with the most inliers among `iterations` 4-point hypotheses, refined by a
/// least-squares fit to its inliers (and its inliers counted again). Not found: fewer than
/// 4 points, or no hypothesis within the radius range.
SphereFit fitSphereRansac(const std::vector<Eigen::Vector3f>& points,
                          const SphereRansacConfig& config = {});

struct ClusterSplitConfig {
  SphereRansacConfig ransac;
  /// Clusters smaller than twice this are not split; a sphere after the first needs this
  /// many inliers (among the points the spheres before it leave) to be a part of its own.
  /// (After the points are reassigned to the nearest sphere a part may come out smaller; the
  /// sizing chain then drops it as a small cluster, counted.)
  int min_cluster_points = 30;
  /// And this fraction of its cluster (stray spheres through clutter are small).
  double min_part_fraction = 0.05;
  /// A cluster whose first sphere leaves less than this fraction of it is one fruitlet.
  double min_outlier_fraction = 0.1;
  /// Points within this of a sphere are its. An elongated fruitlet's (e <= 1.15) ends lie
  /// within ~1.2 mm of its best sphere; points farther than this from every part's sphere
  /// after a split (the stereo bridge between fruitlets) become noise.
  double max_assignment_distance_m = 0.0015;
  int max_parts = 6;  ///< at most this many parts split off one cluster
  void validate() const;
};

/// Splits, in place, the clusters of `labels` (DBSCAN's: kDbscanNoise or 0..k-1) that hold
/// more than one fruitlet; a part split off gets the next free label, and the points of a
/// split cluster far from every part's sphere become noise. Clusters not split are left as
/// they are. Returns how many parts were split off.
std::size_t splitMergedClusters(const std::vector<Eigen::Vector3f>& points,
                                std::vector<int>& labels, const ClusterSplitConfig& config = {});

}  // namespace fvp::host::sizing
