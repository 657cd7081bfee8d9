#include "fvp/host/map/scan_points.h"

namespace fvp::host::map {

std::vector<accel::ScanPoint> prepareScanPoints(const LabeledClouds& clouds, double max_range_m,
                                                ScanStats& stats) {
  const Eigen::Vector3d& sensor_origin_m = clouds.sensor_origin_m;
  std::vector<accel::ScanPoint> points;
  points.reserve(clouds.roi_points_m.size() + clouds.other_points_m.size());
  auto add = [&](const std::vector<Eigen::Vector3f>& cloud, unsigned flags) {
    for (const Eigen::Vector3f& p : cloud) {
      ++stats.points;
      if (!p.allFinite()) {
        ++stats.skipped_invalid;
        continue;
      }
      const Eigen::Vector3d d = p.cast<double>() - sensor_origin_m;
      const double range = d.norm();
      if (range > max_range_m) {
        ++stats.truncated;
        const Eigen::Vector3d end = sensor_origin_m + d * (max_range_m / range);
        points.push_back({static_cast<float>(end.x()), static_cast<float>(end.y()),
                          static_cast<float>(end.z()), 0u});
        continue;
      }
      points.push_back({p.x(), p.y(), p.z(), FVP_POINT_HIT | flags});
    }
  };
  add(clouds.roi_points_m, FVP_POINT_ROI);
  add(clouds.other_points_m, 0u);
  return points;
}

}  // namespace fvp::host::map
