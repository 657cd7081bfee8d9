#include "fvp/host/sizing/sphere_ransac.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <stdexcept>

#include "fvp/host/sizing/point_filters.h"

namespace fvp::host::sizing {
namespace {

constexpr int kRefinementRounds = 5;

std::vector<std::size_t> inliersOf(const std::vector<Eigen::Vector3f>& points,
                                   const Eigen::Vector3d& center_m, double radius_m,
                                   double tolerance_m) {
  std::vector<std::size_t> inliers;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (std::abs((points[i].cast<double>() - center_m).norm() - radius_m) <= tolerance_m)
      inliers.push_back(i);
  return inliers;
}

template <typename T>
std::vector<T> gather(const std::vector<T>& values, const std::vector<std::size_t>& indices) {
  std::vector<T> out;
  out.reserve(indices.size());
  for (std::size_t i : indices) out.push_back(values[i]);
  return out;
}

}  // namespace

void SphereRansacConfig::validate() const {
  if (!(inlier_tolerance_m > 0.0))
    throw std::invalid_argument("sphere RANSAC: inlier_tolerance_m > 0");
  if (!(min_radius_m >= 0.0 && max_radius_m > min_radius_m))
    throw std::invalid_argument("sphere RANSAC: 0 <= min_radius_m < max_radius_m");
  if (iterations < 1) throw std::invalid_argument("sphere RANSAC: iterations >= 1");
}

void ClusterSplitConfig::validate() const {
  ransac.validate();
  if (min_cluster_points < 4) throw std::invalid_argument("cluster split: min_cluster_points >= 4");
  if (!(min_outlier_fraction > 0.0 && min_outlier_fraction < 1.0))
    throw std::invalid_argument("cluster split: min_outlier_fraction in (0, 1)");
  if (!(min_part_fraction >= 0.0 && min_part_fraction < 1.0))
    throw std::invalid_argument("cluster split: min_part_fraction in [0, 1)");
  if (max_parts < 1) throw std::invalid_argument("cluster split: max_parts >= 1");
  if (!(max_assignment_distance_m > 0.0))
    throw std::invalid_argument("cluster split: max_assignment_distance_m > 0");
}

bool fitSphere(const std::vector<Eigen::Vector3f>& points, Eigen::Vector3d& center_m,
               double& radius_m) {
  if (points.size() < 4) return false;
  // |p|^2 = 2 c.p + (r^2 - |c|^2): linear in (c, k); centred for conditioning.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p.cast<double>();
  mean /= double(points.size());
  Eigen::MatrixXd A(points.size(), 4);
  Eigen::VectorXd b(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d q = points[i].cast<double>() - mean;
    A.row(i) << 2.0 * q.x(), 2.0 * q.y(), 2.0 * q.z(), 1.0;
    b[i] = q.squaredNorm();
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  if (qr.rank() < 4) return false;  // coplanar or repeated points: no unique sphere
  const Eigen::Vector4d x = qr.solve(b);
  if (!x.allFinite()) return false;
  const Eigen::Vector3d c = x.head<3>();
  const double r2 = x[3] + c.squaredNorm();
  if (!(r2 > 0.0)) return false;
  center_m = c + mean;
  radius_m = std::sqrt(r2);
  return true;
}

SphereFit fitSphereRansac(const std::vector<Eigen::Vector3f>& points,
                          const SphereRansacConfig& config) {
  config.validate();
  SphereFit best;
  if (points.size() < 4) return best;
  std::mt19937_64 rng(config.seed);
  std::uniform_int_distribution<std::size_t> pick(0, points.size() - 1);
  const auto inRange = [&](double r) {
    return r >= config.min_radius_m && r <= config.max_radius_m;
  };
  std::size_t best_count = 0;
  std::vector<Eigen::Vector3f> sample(4);
  for (int it = 0; it < config.iterations; ++it) {
    for (auto& s : sample) s = points[pick(rng)];
    Eigen::Vector3d c;
    double r = 0.0;
    if (!fitSphere(sample, c, r) || !inRange(r)) continue;
    // Count without storing: most hypotheses lose.
    std::size_t count = 0;
    for (const auto& p : points)
      count += std::abs((p.cast<double>() - c).norm() - r) <= config.inlier_tolerance_m ? 1 : 0;
    if (count > best_count) {
      best_count = count;
      best.found = true;
      best.center_m = c;
      best.radius_m = r;
    }
  }
  if (!best.found) return best;
  best.inliers = inliersOf(points, best.center_m, best.radius_m, config.inlier_tolerance_m);
  // Least squares over the inliers, then over the new inliers, until they settle: a
  // hypothesis from 4 noisy points is off by a fraction of the tolerance. The count may drop
  // by the strays the rough hypothesis took in; a fit that loses many points has diverged.
  for (int round = 0; round < kRefinementRounds; ++round) {
    Eigen::Vector3d c;
    double r = 0.0;
    if (!fitSphere(gather(points, best.inliers), c, r) || !inRange(r)) break;
    std::vector<std::size_t> refined = inliersOf(points, c, r, config.inlier_tolerance_m);
    if (10 * refined.size() < 9 * best.inliers.size()) break;
    const bool same = refined == best.inliers;
    best.center_m = c;
    best.radius_m = r;
    best.inliers = std::move(refined);
    if (same) break;
  }
  return best;
}

namespace {

// Splits the cluster `members` (indices into `points`) by sequential RANSAC: the sphere with
// the most inliers, then the sphere with the most inliers among the points farther than
// max_assignment_distance_m from it, and so on while each new sphere is a fruitlet of its
// own. A sphere centred inside one found already is a shell of that fruitlet (a fused
// surface millimetres thick, an elongated fruitlet's end): its points are set aside and the
// search goes on, so that a fruitlet found later is not lost with them. With two spheres or
// more, each point goes to the nearest sphere (the first keeps the cluster's label, the
// others get labels from `next_label`), and points far from every sphere (the stereo bridge
// between fruitlets) become noise. Returns the parts split off.
std::size_t splitCluster(const std::vector<Eigen::Vector3f>& points,
                         const std::vector<std::size_t>& members, std::vector<int>& labels,
                         int& next_label, const ClusterSplitConfig& config) {
  if (int(members.size()) < 2 * config.min_cluster_points) return 0;
  const std::vector<Eigen::Vector3f> cloud = gather(points, members);
  const auto offSphere = [](const Eigen::Vector3f& p, const SphereFit& s) {
    return std::abs((p.cast<double>() - s.center_m).norm() - s.radius_m);
  };
  std::vector<SphereFit> spheres;
  std::vector<std::size_t> remaining(cloud.size());  // indices into cloud
  for (std::size_t i = 0; i < cloud.size(); ++i) remaining[i] = i;
  const double min_part_points =
      std::max<double>(config.min_cluster_points, config.min_part_fraction * cloud.size());
  const auto explainedBy = [&](const SphereFit& sphere) {
    std::vector<std::size_t> unexplained;
    for (std::size_t i : remaining)
      if (offSphere(cloud[i], sphere) > config.max_assignment_distance_m) unexplained.push_back(i);
    remaining = std::move(unexplained);
  };
  // Every round takes at least min_part_points away; shells are bounded like parts.
  for (int shells = 0; int(spheres.size()) <= config.max_parts && shells < config.max_parts;) {
    const std::vector<Eigen::Vector3f> rest = gather(cloud, remaining);
    SphereFit fit = fitSphereRansac(rest, config.ransac);
    if (!fit.found) break;
    if (!spheres.empty()) {
      // Another fruitlet: enough points (stray spheres through the bridge between fruitlets
      // are small), and no overlap with one found already (each centre outside the other's
      // sphere).
      if (double(fit.inliers.size()) < min_part_points) break;
      const bool overlaps = std::any_of(spheres.begin(), spheres.end(), [&](const SphereFit& s) {
        return (s.center_m - fit.center_m).norm() < std::max(s.radius_m, fit.radius_m);
      });
      if (overlaps) {
        ++shells;
        explainedBy(fit);
        if (double(remaining.size()) < min_part_points) break;
        continue;
      }
    }
    spheres.push_back(std::move(fit));
    explainedBy(spheres.back());
    // One sphere explaining nearly all of it: one fruitlet (an elongated one's ends lie
    // within max_assignment_distance_m of its best sphere).
    if (spheres.size() == 1 &&
        double(remaining.size()) < config.min_outlier_fraction * double(cloud.size()))
      return 0;
    if (double(remaining.size()) < min_part_points) break;
  }
  if (spheres.size() < 2) return 0;

  const int first_label = labels[members.front()];
  std::vector<int> sphere_labels{first_label};
  for (std::size_t k = 1; k < spheres.size(); ++k) sphere_labels.push_back(next_label++);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    double nearest = std::numeric_limits<double>::infinity();
    int to = kDbscanNoise;
    for (std::size_t k = 0; k < spheres.size(); ++k) {
      const double d = offSphere(cloud[i], spheres[k]);
      if (d < nearest) nearest = d, to = sphere_labels[k];
    }
    labels[members[i]] = nearest <= config.max_assignment_distance_m ? to : kDbscanNoise;
  }
  return spheres.size() - 1;
}

}  // namespace

std::size_t splitMergedClusters(const std::vector<Eigen::Vector3f>& points,
                                std::vector<int>& labels, const ClusterSplitConfig& config) {
  config.validate();
  if (labels.size() != points.size())
    throw std::invalid_argument("cluster split: one label per point expected");
  auto clusters = clusterMembers(labels);
  int next_label = clusters.empty() ? 0 : clusters.rbegin()->first + 1;
  std::size_t split = 0;
  for (const auto& [label, members] : clusters)
    split += splitCluster(points, members, labels, next_label, config);
  return split;
}

}  // namespace fvp::host::sizing
