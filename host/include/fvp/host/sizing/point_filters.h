// Point-cloud filters of the sizing chain (paper, "Fruitlet Sizing"), with nanoflann k-d
// trees for the neighbour queries: statistical outlier removal (Open3D's semantics) and
// DBSCAN (Ester et al. 1996; scikit-learn's semantics: min_samples counts the point itself).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <map>
#include <vector>

namespace fvp::host::sizing {

inline constexpr int kDefaultOutlierNeighbours = 20;
inline constexpr double kDefaultOutlierStdRatio = 2.0;

/// Indices of the points kept: those whose mean distance to their k nearest neighbours (the
/// point itself included, as Open3D counts) is at most mean + std_ratio * std over all points.
std::vector<std::size_t> statisticalOutlierInliers(const std::vector<Eigen::Vector3f>& points,
                                                   int neighbours = kDefaultOutlierNeighbours,
                                                   double std_ratio = kDefaultOutlierStdRatio);

inline constexpr int kDbscanNoise = -1;

/// Cluster label of every point (0, 1, ... in order of the first core point found, scanning
/// the points in order), kDbscanNoise for noise.
std::vector<int> dbscan(const std::vector<Eigen::Vector3f>& points, double eps_m, int min_samples);

/// The indices of each cluster's points, by label in ascending order; noise left out.
std::map<int, std::vector<std::size_t>> clusterMembers(const std::vector<int>& labels);

/// Mean distance from each point of `from` to its nearest point of `to` (k-d tree over
/// `to`); infinity when either is empty.
double meanNearestDistance_m(const std::vector<Eigen::Vector3f>& from,
                             const std::vector<Eigen::Vector3f>& to);
/// Symmetric chamfer distance: the mean of meanNearestDistance_m both ways.
double chamferDistance_m(const std::vector<Eigen::Vector3f>& a,
                         const std::vector<Eigen::Vector3f>& b);

}  // namespace fvp::host::sizing
