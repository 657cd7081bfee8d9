#include "fvp/host/sizing/instance_split.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <queue>
#include <stdexcept>

#include "fvp/host/core/point_kd_tree.h"
#include "fvp/host/sizing/point_filters.h"

namespace fvp::host::sizing {
namespace {

constexpr int kUnseen = -1;

/// The instance id under each member as `view` sees it: kUnseen where the point is out of
/// the image, has no valid disparity or lies off the view's surface (hidden), else the id
/// (0: background). `inner`, when asked for (seeds): whether the id is the same over the
/// seed margin's window.
void seenInstances(const std::vector<Eigen::Vector3f>& points,
                   const std::vector<std::size_t>& members, const SizingView& view,
                   const InstanceSplitConfig& config, std::vector<int>& ids,
                   std::vector<char>* inner = nullptr) {
  ids.assign(members.size(), kUnseen);
  if (inner) inner->assign(members.size(), 0);
  const cv::Mat& instances = view.fruitlet_instances;
  const cv::Mat& disparity = view.disparity_px;
  const StereoIntrinsics& K = view.intrinsics;
  const Eigen::Isometry3d T_camera_world = view.T_world_camera.inverse();
  const int m = config.seed_margin_px;
  for (std::size_t i = 0; i < members.size(); ++i) {
    const Eigen::Vector3d p = T_camera_world * points[members[i]].cast<double>();
    const auto px = K.project(p);
    if (!px) continue;
    const int u = int(std::lround(px->x())), v = int(std::lround(px->y()));
    if (u < 0 || v < 0 || u >= instances.cols || v >= instances.rows) continue;
    const float d = disparity.at<float>(v, u);
    if (!(d > 0.0f) || !std::isfinite(d)) continue;
    if (std::abs(K.depthFromDisparity(d) - p.z()) > config.visibility_tolerance_m) continue;
    const int id = instances.at<std::uint16_t>(v, u);
    ids[i] = id;
    if (!inner || id == 0 || u < m || v < m || u + m >= instances.cols || v + m >= instances.rows)
      continue;
    bool same = true;
    for (int y = v - m; y <= v + m && same; ++y)
      for (int x = u - m; x <= u + m && same; ++x) same = instances.at<std::uint16_t>(y, x) == id;
    (*inner)[i] = same;
  }
}

/// How many of the seen points fall on each instance, and how many are seen.
struct InstanceCounts {
  std::map<int, int> per_instance;
  int seen = 0;
};

InstanceCounts countInstances(const std::vector<int>& ids) {
  InstanceCounts c;
  for (int id : ids) {
    if (id == kUnseen) continue;
    ++c.seen;
    if (id > 0) ++c.per_instance[id];
  }
  return c;
}

/// The ids holding a part's worth of the seen points, most points first; fewer than two:
/// the view does not split the cluster.
std::vector<int> partInstances(const std::vector<int>& ids, const InstanceSplitConfig& config) {
  const auto [count, seen] = countInstances(ids);
  const double needed = std::max<double>(config.min_part_points, config.min_part_fraction * seen);
  std::vector<std::pair<int, int>> large;
  for (const auto& [id, n] : count)
    if (n >= needed) large.emplace_back(n, id);
  std::sort(large.rbegin(), large.rend());
  std::vector<int> out;
  for (const auto& [n, id] : large) out.push_back(id);
  return out;
}

/// Each member's part: the seed it reaches first along the surface graph (edges between
/// points within neighbour_radius_m, weighted by length); -1 where no seed reaches.
std::vector<int> growParts(const std::vector<Eigen::Vector3f>& points,
                           const std::vector<std::size_t>& members,
                           const std::vector<int>& seed_part, double radius_m) {
  std::vector<Eigen::Vector3f> cloud;
  cloud.reserve(members.size());
  for (std::size_t i : members) cloud.push_back(points[i]);
  const PointCloudAdaptor adaptor{cloud};
  PointKdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  std::vector<double> distance(cloud.size(), std::numeric_limits<double>::infinity());
  std::vector<int> part(cloud.size(), -1);
  using Entry = std::pair<double, std::size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (seed_part[i] >= 0) {
      distance[i] = 0.0;
      part[i] = seed_part[i];
      queue.emplace(0.0, i);
    }
  const float r2 = float(radius_m * radius_m);
  std::vector<std::pair<std::size_t, float>> matches;
  std::vector<char> settled(cloud.size(), 0);
  while (!queue.empty()) {
    const auto [d, i] = queue.top();
    queue.pop();
    if (settled[i]) continue;
    settled[i] = 1;
    matches.clear();
    tree.radiusSearch(cloud[i].data(), r2, matches, nanoflann::SearchParams());
    for (const auto& [j, d2] : matches) {
      const double through = d + std::sqrt(double(d2));
      if (through < distance[j]) {
        distance[j] = through;
        part[j] = part[i];
        queue.emplace(through, j);
      }
    }
  }
  return part;
}

/// The parts of one cluster (members: indices into points), each split again until none
/// splits or max_parts are out; a cluster that does not split is one part.
void splitRecursively(const std::vector<Eigen::Vector3f>& points, std::vector<std::size_t> members,
                      const std::vector<SizingView>& views, const InstanceSplitConfig& config,
                      std::vector<std::vector<std::size_t>>& parts) {
  std::vector<int> ids, best_ids;
  std::vector<char> inner, best_inner;
  std::vector<int> best_instances;
  std::size_t best_second = 0;
  int splitting_views = 0;
  if (int(members.size()) >= 2 * config.min_part_points && int(parts.size()) <= config.max_parts) {
    for (const SizingView& view : views) {
      if (view.fruitlet_instances.empty()) continue;
      seenInstances(points, members, view, config, ids, &inner);
      const std::vector<int> instances = partInstances(ids, config);
      if (instances.size() < 2) continue;
      ++splitting_views;
      const std::size_t second =
          std::count(ids.begin(), ids.end(), instances[1]);  // the weaker side's points
      if (second > best_second) {
        best_second = second;
        best_ids = ids;
        best_inner = inner;
        best_instances = instances;
      }
    }
  }
  if (splitting_views < config.min_splitting_views) {
    parts.push_back(std::move(members));
    return;
  }
  std::vector<int> seed_part(members.size(), -1);
  for (std::size_t i = 0; i < members.size(); ++i) {
    if (!best_inner[i]) continue;
    const auto it = std::find(best_instances.begin(), best_instances.end(), best_ids[i]);
    if (it != best_instances.end()) seed_part[i] = int(it - best_instances.begin());
  }
  const std::vector<int> grown = growParts(points, members, seed_part, config.neighbour_radius_m);
  std::vector<std::vector<std::size_t>> split(best_instances.size());
  for (std::size_t i = 0; i < members.size(); ++i)
    if (grown[i] >= 0) split[std::size_t(grown[i])].push_back(members[i]);
  // Every part a fruitlet's worth of points, or no split (a part with too few seeds).
  if (std::any_of(split.begin(), split.end(), [&](const std::vector<std::size_t>& s) {
        return int(s.size()) < config.min_part_points;
      })) {
    parts.push_back(std::move(members));
    return;
  }
  for (auto& s : split) splitRecursively(points, std::move(s), views, config, parts);
}

}  // namespace

void InstanceSplitConfig::validate() const {
  if (min_part_points < 4) throw std::invalid_argument("instance split: min_part_points >= 4");
  if (!(min_part_fraction >= 0.0 && min_part_fraction < 0.5))
    throw std::invalid_argument("instance split: min_part_fraction in [0, 0.5)");
  if (min_splitting_views < 1)
    throw std::invalid_argument("instance split: min_splitting_views >= 1");
  if (!(visibility_tolerance_m > 0.0))
    throw std::invalid_argument("instance split: visibility_tolerance_m > 0");
  if (!(neighbour_radius_m > 0.0))
    throw std::invalid_argument("instance split: neighbour_radius_m > 0");
  if (seed_margin_px < 0) throw std::invalid_argument("instance split: seed_margin_px >= 0");
  if (max_parts < 1) throw std::invalid_argument("instance split: max_parts >= 1");
}

std::vector<int> dominantInstances(const std::vector<Eigen::Vector3f>& points,
                                   const std::vector<SizingView>& views,
                                   const InstanceSplitConfig& config) {
  std::vector<std::size_t> all(points.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  std::vector<int> out(views.size(), 0), ids;
  for (std::size_t v = 0; v < views.size(); ++v) {
    if (views[v].fruitlet_instances.empty()) continue;
    seenInstances(points, all, views[v], config, ids);
    const auto [count, seen] = countInstances(ids);
    for (const auto& [id, n] : count)
      if (2 * n >= seen && 3 * n >= config.min_part_points) out[v] = id;
  }
  return out;
}

bool sameInstance(const std::vector<int>& a, const std::vector<int>& b) {
  int same = 0, different = 0;
  for (std::size_t v = 0; v < std::min(a.size(), b.size()); ++v) {
    if (a[v] == 0 || b[v] == 0) continue;
    (a[v] == b[v] ? same : different) += 1;
  }
  return same >= 2 && same > different;
}

std::size_t splitByInstances(const std::vector<Eigen::Vector3f>& points, std::vector<int>& labels,
                             const std::vector<SizingView>& views,
                             const InstanceSplitConfig& config) {
  config.validate();
  if (labels.size() != points.size())
    throw std::invalid_argument("instance split: one label per point expected");
  for (const SizingView& view : views)
    if (!view.fruitlet_instances.empty() &&
        (view.fruitlet_instances.type() != CV_16U || view.disparity_px.type() != CV_32F ||
         view.disparity_px.size() != view.fruitlet_instances.size()))
      throw std::invalid_argument(
          "instance split: instance ids CV_16U and disparity CV_32F of one size expected");
  auto clusters = clusterMembers(labels);
  int next_label = clusters.empty() ? 0 : clusters.rbegin()->first + 1;
  std::size_t split_off = 0;
  for (auto& [label, members] : clusters) {
    std::vector<std::vector<std::size_t>> parts;
    splitRecursively(points, members, views, config, parts);
    if (parts.size() < 2) continue;
    for (std::size_t i : members) labels[i] = kDbscanNoise;  // points no seed reached
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const int part_label = k == 0 ? label : next_label++;
      for (std::size_t i : parts[k]) labels[i] = part_label;
    }
    split_off += parts.size() - 1;
  }
  return split_off;
}

}  // namespace fvp::host::sizing
