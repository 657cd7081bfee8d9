#include "fvp/host/perception/cluster_region_image.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fvp::host {

namespace {

// Exact image interval of a sphere along one axis: the tangent planes through the camera's
// other image axis, x = k z, satisfy (c_x - k c_z)^2 = r^2 (1 + k^2). False when the sphere
// reaches the camera plane (the interval is unbounded).
bool tangentInterval(double c_x, double c_z, double r, double& k_min, double& k_max) {
  const double a = c_z * c_z - r * r;
  if (!(c_z > 0.0) || !(a > 0.0)) return false;
  const double disc = r * std::sqrt(std::max(0.0, c_x * c_x + a));
  k_min = (c_x * c_z - disc) / a;
  k_max = (c_x * c_z + disc) / a;
  return true;
}

}  // namespace

cv::Rect clusterRegionImageBounds(const ClusterRegion& region, const StereoIntrinsics& K,
                                  const Eigen::Isometry3d& T_world_camera) {
  const cv::Rect image(0, 0, K.width_px, K.height_px);
  const Eigen::Vector3d c = T_world_camera.inverse() * region.center_m();
  if (c.z() + region.radius_m() <= 0.0) return {};  // entirely behind the camera
  double kx0, kx1, ky0, ky1;
  if (!tangentInterval(c.x(), c.z(), region.radius_m(), kx0, kx1) ||
      !tangentInterval(c.y(), c.z(), region.radius_m(), ky0, ky1))
    return image;  // the sphere reaches the camera plane: it may fill the view
  const double lim = 1e6;
  auto px = [&](double k, double f, double c0) { return std::clamp(f * k + c0, -lim, lim); };
  const int x0 = static_cast<int>(std::floor(px(kx0, K.fx_px, K.cx_px)));
  const int x1 = static_cast<int>(std::ceil(px(kx1, K.fx_px, K.cx_px))) + 1;
  const int y0 = static_cast<int>(std::floor(px(ky0, K.fy_px, K.cy_px)));
  const int y1 = static_cast<int>(std::ceil(px(ky1, K.fy_px, K.cy_px))) + 1;
  return cv::Rect(cv::Point(x0, y0), cv::Point(x1, y1)) & image;
}

std::optional<DisparityWindow> clusterRegionDisparityWindow(const ClusterRegion& region,
                                                            const StereoIntrinsics& K,
                                                            const Eigen::Isometry3d& T_world_camera,
                                                            double depth_margin_m, int pad_px) {
  const double z = (T_world_camera.inverse() * region.center_m()).z();
  const double farthest = z + region.radius_m() + depth_margin_m;
  if (!(farthest > 0.0)) return std::nullopt;
  DisparityWindow w;
  // A far side at the camera plane has no bounded disparity: then no window.
  const double far_side_px = std::floor(K.fx_px * K.baseline_m / farthest);
  if (!(far_side_px < 1e6)) return std::nullopt;
  w.min_px = static_cast<int>(far_side_px) - pad_px;
  w.max_px = std::numeric_limits<int>::max();
  return w;
}

}  // namespace fvp::host
