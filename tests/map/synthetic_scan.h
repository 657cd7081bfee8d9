// A synthetic depth frame for map tests: a pinhole camera looking at the Cluster Region,
// fruitlet spheres inside it (ROI points), a leaf disc and a back plane (other points).
// Deterministic for a seed; a few points are jittered with sensor-like noise.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "fvp/host/core/labeled_clouds.h"

namespace fvp::host::map::testing {

/// The clouds of one view as MapEngine::integrate takes them.
inline LabeledClouds makeClouds(const Eigen::Vector3d& origin_m,
                                std::vector<Eigen::Vector3f> roi_points_m,
                                std::vector<Eigen::Vector3f> other_points_m) {
  LabeledClouds clouds;
  clouds.sensor_origin_m = origin_m;
  clouds.roi_points_m = std::move(roi_points_m);
  clouds.other_points_m = std::move(other_points_m);
  return clouds;
}

struct SyntheticScan {
  Eigen::Vector3d origin_m;
  std::vector<Eigen::Vector3f> roi_points_m;
  std::vector<Eigen::Vector3f> other_points_m;
  LabeledClouds clouds() const { return makeClouds(origin_m, roi_points_m, other_points_m); }
};

struct SyntheticWorld {
  Eigen::Vector3d region_center_m{0.0, 0.0, 0.3};
  std::vector<Eigen::Vector4d> fruitlets;  ///< centre xyz, radius
  double back_plane_offset_m = 0.08;       ///< behind the region centre, seen from the camera
};

inline SyntheticWorld makeWorld(std::uint64_t seed, const Eigen::Vector3d& region_center_m,
                                int fruitlet_count = 5) {
  SyntheticWorld w;
  w.region_center_m = region_center_m;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> offset(-0.025, 0.025), radius(0.004, 0.009);
  for (int i = 0; i < fruitlet_count; ++i) {
    w.fruitlets.emplace_back(region_center_m.x() + offset(rng), region_center_m.y() + offset(rng),
                             region_center_m.z() + offset(rng), radius(rng));
  }
  return w;
}

/// width x height rays from `origin_m` towards the region centre over a field of view of
/// fov_rad; each ray ends at the nearest fruitlet (ROI) or at the back plane (other).
inline SyntheticScan renderScan(const SyntheticWorld& w, const Eigen::Vector3d& origin_m, int width,
                                int height, double fov_rad, std::uint64_t seed) {
  SyntheticScan scan;
  scan.origin_m = origin_m;
  const Eigen::Vector3d forward = (w.region_center_m - origin_m).normalized();
  Eigen::Vector3d up =
      std::abs(forward.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d right = forward.cross(up).normalized();
  up = right.cross(forward);
  const double plane_distance = (w.region_center_m - origin_m).norm() + w.back_plane_offset_m;
  const double f = 0.5 * width / std::tan(0.5 * fov_rad);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.0003);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const Eigen::Vector3d d =
          (forward * f + right * (u + 0.5 - 0.5 * width) + up * (v + 0.5 - 0.5 * height))
              .normalized();
      double best = std::numeric_limits<double>::infinity();
      for (const Eigen::Vector4d& s : w.fruitlets) {
        const Eigen::Vector3d oc = origin_m - s.head<3>();
        const double b = oc.dot(d), c = oc.squaredNorm() - s[3] * s[3];
        const double disc = b * b - c;
        if (disc < 0.0) continue;
        const double t = -b - std::sqrt(disc);
        if (t > 0.0 && t < best) best = t;
      }
      const bool roi = std::isfinite(best);
      if (!roi) best = plane_distance / d.dot(forward);
      const Eigen::Vector3d p = origin_m + d * (best + noise(rng));
      (roi ? scan.roi_points_m : scan.other_points_m).push_back(p.cast<float>());
    }
  }
  return scan;
}

}  // namespace fvp::host::map::testing
