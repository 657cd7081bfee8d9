// Ideal views of spheres for TSDF tests: exact z-depth and a full mask of the nearest
// sphere per pixel, from a pinhole camera at T_world_camera (the simulated camera's
// intrinsics).
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#include "fvp/host/core/stereo_intrinsics.h"

namespace fvp::testing {

struct SphereView {
  cv::Mat depth, mask;  ///< CV_32F z-depth (0: no sphere), CV_8U 255 on a sphere
  cv::Mat instances;    ///< CV_16U: 1 + the index of the sphere seen, 0 none
  host::StereoIntrinsics in;
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
};

/// spheres: centre xyz and radius, metres, world frame.
inline SphereView renderSpheres(const std::vector<Eigen::Vector4d>& spheres,
                                const Eigen::Isometry3d& T_world_camera) {
  SphereView v;
  v.T_world_camera = T_world_camera;
  v.depth = cv::Mat(v.in.height_px, v.in.width_px, CV_32F, cv::Scalar(0));
  v.mask = cv::Mat(v.in.height_px, v.in.width_px, CV_8U, cv::Scalar(0));
  v.instances = cv::Mat(v.in.height_px, v.in.width_px, CV_16U, cv::Scalar(0));
  const Eigen::Isometry3d T_camera_world = T_world_camera.inverse();
  for (int y = 0; y < v.in.height_px; ++y)
    for (int x = 0; x < v.in.width_px; ++x) {
      const Eigen::Vector3d d =
          Eigen::Vector3d((x - v.in.cx_px) / v.in.fx_px, (y - v.in.cy_px) / v.in.fy_px, 1.0)
              .normalized();
      double best = INFINITY;
      std::size_t seen = 0;
      for (std::size_t k = 0; k < spheres.size(); ++k) {
        const Eigen::Vector3d c = T_camera_world * Eigen::Vector3d(spheres[k].head<3>());
        const double b = d.dot(c), disc = b * b - (c.squaredNorm() - spheres[k][3] * spheres[k][3]);
        if (disc >= 0 && b - std::sqrt(disc) < best) best = b - std::sqrt(disc), seen = k;
      }
      if (!std::isfinite(best)) continue;
      v.depth.at<float>(y, x) = float(best * d.z());
      v.mask.at<std::uint8_t>(y, x) = 255;
      v.instances.at<std::uint16_t>(y, x) = static_cast<std::uint16_t>(seen + 1);
    }
  return v;
}

}  // namespace fvp::testing
