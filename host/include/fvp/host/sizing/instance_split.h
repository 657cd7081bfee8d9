// The split of DBSCAN clusters by the views' instance segmentations (docs/sizing.md,
// "Touching fruitlets and instance masks").
//
// Touching fruitlets fuse into one DBSCAN cluster. The sphere split (sphere_ransac.h) takes
// them apart when their surfaces are crisp, but where views disagree by a millimetre or two
// (arm and hand-eye errors, a fruitlet swinging in the wind) the fused surface is millimetres
// thick and no sphere stands out. An instance segmentation (a trained network's masks, one
// id per fruitlet) tells them apart in the images: a cluster whose visible points fall on
// two instances or more in several views holds that many fruitlets. Its points are split
// from the best such view: the points that view sees well inside each instance seed a part,
// and every other point joins the part it reaches first along the cluster's surface (the
// seeds' geodesic Voronoi regions: touching fruitlets meet at a narrow neck). Each part is
// then checked again, against every view, until none splits.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "fvp/host/sizing/sizing_view.h"

namespace fvp::host::sizing {

struct InstanceSplitConfig {
  /// A second instance counts in a view when at least this many of the cluster's visible
  /// points fall on it (the sizing chain's smallest cluster)...
  int min_part_points = 30;
  /// ...and this fraction of the cluster's visible points in that view.
  double min_part_fraction = 0.1;
  /// Views that must show the cluster on two instances or more: a fruitlet that swung onto
  /// its neighbour's outline in one view does not split.
  int min_splitting_views = 2;
  /// A point is seen by a view when its depth there is within this of the view's stereo
  /// depth at its pixel: the fused surface lies within a few millimetres of where one view
  /// sees it (a 2 mm wind swing, registration's sub-millimetre residual); a point behind
  /// another fruitlet lies a fruitlet's radius (>= 3 mm) or more behind it.
  double visibility_tolerance_m = 0.003;
  /// Surface neighbours for the geodesic growth: DBSCAN's eps, so a part is connected.
  double neighbour_radius_m = 0.002;
  /// Seeds lie at least this far inside their instance's outline (boundary errors).
  int seed_margin_px = 2;
  int max_parts = 6;  ///< at most this many parts split off one cluster
  void validate() const;
};

/// Splits, in place, the clusters of `labels` (kDbscanNoise or >= 0) that the views'
/// instance ids (SizingView::fruitlet_instances; views without them are skipped) show to
/// hold more than one fruitlet. A part split off gets the next free label; points no seed
/// reaches become noise. Returns how many parts were split off.
std::size_t splitByInstances(const std::vector<Eigen::Vector3f>& points, std::vector<int>& labels,
                             const std::vector<SizingView>& views,
                             const InstanceSplitConfig& config = {});

/// Per view, the instance a detection's points lie on where the view sees them (seen as in
/// the split): the id holding at least half of the seen points and min_part_points / 3 of
/// them; 0 where none does or the view carries no instances.
std::vector<int> dominantInstances(const std::vector<Eigen::Vector3f>& points,
                                   const std::vector<SizingView>& views,
                                   const InstanceSplitConfig& config = {});

/// Two detections are one fruitlet seen twice when the views see them on one instance in at
/// least two views and more often than on two (dominantInstances of each).
bool sameInstance(const std::vector<int>& a, const std::vector<int>& b);

}  // namespace fvp::host::sizing
