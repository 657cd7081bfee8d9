#include "fvp/host/perception/cloud_projector.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

namespace fvp::host {

LabeledClouds CloudProjector::project(const cv::Mat& disparity_px, const cv::Mat& roi_mask,
                                      const StereoIntrinsics& K,
                                      const Eigen::Isometry3d& T_world_camera,
                                      const SampleGrid& grid) const {
  if (disparity_px.type() != CV_32F)
    throw std::invalid_argument("CloudProjector::project: disparity must be CV_32F");
  if (!roi_mask.empty() && (roi_mask.type() != CV_8U || roi_mask.size() != disparity_px.size()))
    throw std::invalid_argument(
        "CloudProjector::project: ROI mask must be CV_8U of the disparity's size");
  if (grid.coarse_step < 1)
    throw std::invalid_argument("CloudProjector::project: coarse_step must be >= 1");
  const auto t0 = std::chrono::steady_clock::now();
  LabeledClouds out;
  out.sensor_origin_m = T_world_camera.translation();
  PerceptionStats& st = out.stats;
  const int step = grid.coarse_step;
  const cv::Rect full = grid.full_res_rect;
  const bool all_full = step == 1;
  const double fb = K.fx_px * K.baseline_m;
  const Eigen::Matrix3d R = T_world_camera.linear();
  const Eigen::Vector3d t = T_world_camera.translation();
  const double half_block = 0.5 * (step - 1);

  for (int v = 0; v < disparity_px.rows; ++v) {
    const float* d_row = disparity_px.ptr<float>(v);
    const uchar* m_row = roi_mask.empty() ? nullptr : roi_mask.ptr<uchar>(v);
    const bool full_row = v >= full.y && v < full.br().y;
    for (int u = 0; u < disparity_px.cols; ++u) {
      double pu = u, pv = v;
      if (!all_full && !(full_row && u >= full.x && u < full.br().x)) {
        if (u % step != 0 || v % step != 0) continue;  // inside a coarse block: not a sample
        pu += half_block;                              // the coarse pixel's centre
        pv += half_block;
      }
      const float d = d_row[u];
      if (!std::isfinite(d)) {
        ++st.nonfinite;
        continue;
      }
      if (d <= 0.0f) {
        ++st.nonpositive;
        continue;
      }
      const double z = fb / d;
      if (z < config_.min_depth_m || z > config_.max_depth_m) {
        ++st.out_of_range;
        continue;
      }
      const Eigen::Vector3d p = R * K.unproject(pu, pv, z) + t;
      if (m_row && m_row[u]) {
        out.roi_points_m.push_back(p.cast<float>());
      } else {
        out.other_points_m.push_back(p.cast<float>());
      }
    }
  }
  st.roi_points = static_cast<std::int64_t>(out.roi_points_m.size());
  st.other_points = static_cast<std::int64_t>(out.other_points_m.size());
  st.projection_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace fvp::host
