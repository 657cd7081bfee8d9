// A nanoflann k-d tree over a vector of float points (nanoflann's dataset adaptor), for the
// nearest-neighbour searches of sizing's filters and view registration.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <nanoflann.hpp>
#include <vector>

namespace fvp::host {

/// The points nanoflann reads: they must outlive the tree.
struct PointCloudAdaptor {
  const std::vector<Eigen::Vector3f>& pts;
  std::size_t kdtree_get_point_count() const { return pts.size(); }
  float kdtree_get_pt(std::size_t i, std::size_t dim) const { return pts[i][dim]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;  // nanoflann computes the bounding box itself
  }
};

using PointKdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointCloudAdaptor>,
                                        PointCloudAdaptor, 3, std::size_t>;

}  // namespace fvp::host
