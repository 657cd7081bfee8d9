// What an earlier visit learned of a cluster, in its tag's frame (docs/season.md, "Visits
// remembered"): the tags stay on the tree, so the tag detected on this visit carries the
// earlier fruitlets and views into this visit's world, however the robot stands today. A
// visit after the first takes the views that sized each fruitlet last time before it plans,
// and its automatic stop looks for each remembered fruitlet: one not found where it was,
// after views aimed at it, is reported gone rather than missed.
#pragma once

#include <Eigen/Geometry>
#include <vector>

namespace fvp::host::nbv {

/// A fruitlet an earlier visit sized: its centre in the cluster tag's frame and its diameter.
struct RememberedFruitlet {
  Eigen::Vector3d center_tag_m = Eigen::Vector3d::Zero();
  double size_mm = 0.0;
};

struct ClusterMemory {
  /// The earlier visit's views to take first, camera poses in the tag's frame (OpenCV optical
  /// frame of the left camera): the fewest of its views that showed each fruitlet well.
  std::vector<Eigen::Isometry3d> T_tag_camera;
  std::vector<RememberedFruitlet> fruitlets;
};

}  // namespace fvp::host::nbv
