#include "fvp/host/sizing/point_filters.h"

#include <cmath>
#include <limits>
#include <memory>

#include "fvp/host/core/point_kd_tree.h"

namespace fvp::host::sizing {
namespace {

using Cloud = PointCloudAdaptor;
using Tree = PointKdTree;

}  // namespace

std::vector<std::size_t> statisticalOutlierInliers(const std::vector<Eigen::Vector3f>& points,
                                                   int neighbours, double std_ratio) {
  std::vector<std::size_t> kept;
  if (points.empty() || neighbours < 1) {
    for (std::size_t i = 0; i < points.size(); ++i) kept.push_back(i);
    return kept;
  }
  const Cloud cloud{points};
  Tree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  const std::size_t k = std::min<std::size_t>(neighbours, points.size());
  std::vector<double> mean_distance(points.size());
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t i = 0; i < std::ptrdiff_t(points.size()); ++i) {
    std::vector<std::size_t> idx(k);
    std::vector<float> d2(k);
    const std::size_t found = tree.knnSearch(points[i].data(), k, idx.data(), d2.data());
    double sum = 0.0;
    for (std::size_t j = 0; j < found; ++j) sum += std::sqrt(double(d2[j]));
    mean_distance[i] = found ? sum / found : 0.0;
  }
  double mean = 0.0;
  for (double d : mean_distance) mean += d;
  mean /= points.size();
  double var = 0.0;
  for (double d : mean_distance) var += (d - mean) * (d - mean);
  const double std = points.size() > 1 ? std::sqrt(var / (points.size() - 1)) : 0.0;
  const double limit = mean + std_ratio * std;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (mean_distance[i] <= limit) kept.push_back(i);
  return kept;
}

std::vector<int> dbscan(const std::vector<Eigen::Vector3f>& points, double eps_m, int min_samples) {
  std::vector<int> label(points.size(), kDbscanNoise);
  if (points.empty()) return label;
  const Cloud cloud{points};
  Tree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  const float r2 = static_cast<float>(eps_m * eps_m);
  // Neighbourhoods once, in parallel (nanoflann's radius is squared for L2).
  std::vector<std::vector<std::size_t>> neighbourhood(points.size());
#pragma omp parallel for schedule(dynamic, 256)
  for (std::ptrdiff_t i = 0; i < std::ptrdiff_t(points.size()); ++i) {
    std::vector<std::pair<std::size_t, float>> matches;
    nanoflann::SearchParams params;
    params.sorted = false;
    tree.radiusSearch(points[i].data(), r2, matches, params);
    auto& n = neighbourhood[i];
    n.reserve(matches.size());
    for (const auto& m : matches) n.push_back(m.first);
    std::sort(n.begin(), n.end());
  }
  std::vector<char> visited(points.size(), 0);
  int next = 0;
  std::vector<std::size_t> frontier;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (visited[i] || int(neighbourhood[i].size()) < min_samples) continue;
    const int id = next++;
    visited[i] = 1;
    label[i] = id;
    frontier.assign(1, i);
    while (!frontier.empty()) {
      const std::size_t p = frontier.back();
      frontier.pop_back();
      if (int(neighbourhood[p].size()) < min_samples) continue;  // border point
      for (std::size_t q : neighbourhood[p]) {
        if (label[q] == kDbscanNoise) label[q] = id;
        if (!visited[q]) {
          visited[q] = 1;
          frontier.push_back(q);
        }
      }
    }
  }
  return label;
}

std::map<int, std::vector<std::size_t>> clusterMembers(const std::vector<int>& labels) {
  std::map<int, std::vector<std::size_t>> members;
  for (std::size_t i = 0; i < labels.size(); ++i)
    if (labels[i] != kDbscanNoise) members[labels[i]].push_back(i);
  return members;
}

double meanNearestDistance_m(const std::vector<Eigen::Vector3f>& from,
                             const std::vector<Eigen::Vector3f>& to) {
  if (from.empty() || to.empty()) return std::numeric_limits<double>::infinity();
  const Cloud cloud{to};
  Tree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  double sum = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : sum)
  for (std::ptrdiff_t i = 0; i < std::ptrdiff_t(from.size()); ++i) {
    std::size_t index;
    float d2;
    tree.knnSearch(from[i].data(), 1, &index, &d2);
    sum += std::sqrt(double(d2));
  }
  return sum / from.size();
}

double chamferDistance_m(const std::vector<Eigen::Vector3f>& a,
                         const std::vector<Eigen::Vector3f>& b) {
  return 0.5 * (meanNearestDistance_m(a, b) + meanNearestDistance_m(b, a));
}

}  // namespace fvp::host::sizing
