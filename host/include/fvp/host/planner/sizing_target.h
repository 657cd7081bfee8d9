// A fruitlet the automatic stop still waits for (docs/planner.md, "Views the stop rule
// needs"): the stop asks every fruitlet for two well-seen images from directions 30 degrees
// apart, and the information gain, which counts unknown voxels, never aims at a fruitlet
// whose surroundings are known. A planner given these targets also samples candidates that
// look at each one from a direction its well-seen images lack, scored by how much of it the
// map predicts the camera would see.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace fvp::host::planner {

struct SizingTarget {
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();  ///< in the maps' frame
  double radius_m = 0.0;
  /// Unit vectors from the fruitlet towards the cameras of its well-seen images, one per image.
  std::vector<Eigen::Vector3d> seen_from;
  /// A new view must lie at least this far from one of seen_from (any view when empty).
  double min_angle_deg = 30.0;
  /// The fraction of the fruitlet an image must show to be well seen (sizing's
  /// well_seen_fraction): a candidate predicted to show less gains nothing.
  double min_visible_fraction = 0.6;
};

/// Whether a camera in direction `direction` (unit, from the fruitlet) adds the view span the
/// target lacks: at least min_angle_deg from one of its well-seen directions, or any
/// direction when it has none.
bool addsViewSpan(const SizingTarget& target, const Eigen::Vector3d& direction);

}  // namespace fvp::host::planner
