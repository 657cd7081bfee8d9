#include "fvp/host/tsdf/tsdf_volume.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <stdexcept>

namespace fvp::host::tsdf {
namespace {

int floorDiv(int a, int b) {
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}

}  // namespace

void TsdfConfig::validate() const {
  if (!(voxel_size_m > 1e-5 && voxel_size_m < 0.1))
    throw std::invalid_argument("tsdf config: voxel_size_m: expected (1e-5, 0.1) m");
  if (!(truncation_m >= voxel_size_m && truncation_m < 1.0))
    throw std::invalid_argument("tsdf config: truncation_m: expected [voxel_size_m, 1) m");
  if (!(max_weight > 0.0f)) throw std::invalid_argument("tsdf config: max_weight: expected > 0");
}

TsdfVolume::TsdfVolume(const TsdfConfig& config) : config_(config) {
  config_.validate();
}

const TsdfVolume::Block* TsdfVolume::findBlock(const std::array<int, 3>& coord) const {
  const auto it = index_.find(coord);
  return it == index_.end() ? nullptr : &blocks_[it->second];
}

cv::Mat depthFromDisparity(const cv::Mat& disparity_px, const StereoIntrinsics& in) {
  cv::Mat depth(disparity_px.size(), CV_32F, cv::Scalar(0.0f));
  const float fb = static_cast<float>(in.fx_px * in.baseline_m);
  for (int v = 0; v < disparity_px.rows; ++v) {
    const float* d = disparity_px.ptr<float>(v);
    float* z = depth.ptr<float>(v);
    for (int u = 0; u < disparity_px.cols; ++u)
      if (std::isfinite(d[u]) && d[u] > 0.0f) z[u] = fb / d[u];
  }
  return depth;
}

TsdfIntegrateStats TsdfVolume::integrate(const cv::Mat& depth_m, const cv::Mat& roi_mask,
                                         const StereoIntrinsics& in,
                                         const Eigen::Isometry3d& T_world_camera) {
  if (depth_m.type() != CV_32F || roi_mask.type() != CV_8U || depth_m.size() != roi_mask.size())
    throw std::invalid_argument(
        "TsdfVolume::integrate: expected CV_32F depth and CV_8U mask of "
        "one size");
  const auto start = std::chrono::steady_clock::now();
  TsdfIntegrateStats stats;
  const double vs = config_.voxel_size_m, trunc = config_.truncation_m;
  const double block_m = vs * kBlockSide;

  // 1. Blocks touched by the truncation band around every ROI point (along its ray).
  std::set<std::array<int, 3>> touched;
  const Eigen::Vector3d eye = T_world_camera.translation();
  for (int v = 0; v < depth_m.rows; ++v) {
    const float* z = depth_m.ptr<float>(v);
    const std::uint8_t* m = roi_mask.ptr<std::uint8_t>(v);
    for (int u = 0; u < depth_m.cols; ++u) {
      if (!m[u] || !(z[u] > 0.0f) || !std::isfinite(z[u])) continue;
      ++stats.roi_pixels;
      const Eigen::Vector3d ray_camera((u - in.cx_px) / in.fx_px, (v - in.cy_px) / in.fy_px, 1.0);
      const Eigen::Vector3d p = T_world_camera * (z[u] * ray_camera);
      const Eigen::Vector3d dir = (p - eye).normalized();
      const int steps = static_cast<int>(std::ceil(2.0 * trunc / (0.5 * block_m))) + 1;
      for (int s = 0; s <= steps; ++s) {
        const Eigen::Vector3d q = p + (-trunc + 2.0 * trunc * s / steps) * dir;
        touched.insert({static_cast<int>(std::floor(q.x() / block_m)),
                        static_cast<int>(std::floor(q.y() / block_m)),
                        static_cast<int>(std::floor(q.z() / block_m))});
      }
    }
  }
  std::vector<std::size_t> work;
  work.reserve(touched.size());
  for (const auto& coord : touched) {
    auto [it, inserted] = index_.try_emplace(coord, blocks_.size());
    if (inserted) {
      blocks_.push_back(
          {coord, std::vector<float>(kBlockVoxels, 0.0f), std::vector<float>(kBlockVoxels, 0.0f)});
      ++stats.blocks_allocated;
    }
    work.push_back(it->second);
  }

  // 2. Projective update of every voxel of those blocks (one thread per block).
  const Eigen::Isometry3d T_camera_world = T_world_camera.inverse();
  const float max_weight = config_.max_weight;
  std::size_t updated = 0;
#pragma omp parallel for schedule(dynamic, 4) reduction(+ : updated)
  for (std::ptrdiff_t w = 0; w < std::ptrdiff_t(work.size()); ++w) {
    Block& b = blocks_[work[w]];
    for (int k = 0; k < kBlockVoxels; ++k) {
      const int x = k % kBlockSide, y = (k / kBlockSide) % kBlockSide,
                zc = k / (kBlockSide * kBlockSide);
      const Eigen::Vector3d center((b.coord[0] * kBlockSide + x + 0.5) * vs,
                                   (b.coord[1] * kBlockSide + y + 0.5) * vs,
                                   (b.coord[2] * kBlockSide + zc + 0.5) * vs);
      const Eigen::Vector3d pc = T_camera_world * center;
      if (!(pc.z() > 0.0)) continue;
      const int u = static_cast<int>(std::lround(in.fx_px * pc.x() / pc.z() + in.cx_px));
      const int v = static_cast<int>(std::lround(in.fy_px * pc.y() / pc.z() + in.cy_px));
      if (u < 0 || v < 0 || u >= depth_m.cols || v >= depth_m.rows) continue;
      if (!roi_mask.at<std::uint8_t>(v, u)) continue;
      const float depth = depth_m.at<float>(v, u);
      if (!(depth > 0.0f) || !std::isfinite(depth)) continue;
      // Projective distance along the viewing ray, in metres.
      const double sdf = (depth - pc.z()) * pc.norm() / pc.z();
      if (sdf < -trunc) continue;
      // voxblox: weight 1/z^2, dropping linearly to 0 from one voxel behind the surface to
      // the truncation distance.
      double weight = 1.0 / (pc.z() * pc.z());
      if (sdf < -vs) weight *= (trunc + sdf) / (trunc - vs);
      if (!(weight > 0.0)) continue;
      const float tsdf = static_cast<float>(std::min(sdf, trunc));
      float& D = b.distance[k];
      float& W = b.weight[k];
      const float wf = static_cast<float>(weight);
      D = (D * W + tsdf * wf) / (W + wf);
      W = std::min(W + wf, max_weight);
      ++updated;
    }
  }
  stats.voxels_updated = updated;
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

std::pair<float, float> TsdfVolume::voxel(const Eigen::Vector3d& p_m) const {
  const double vs = config_.voxel_size_m;
  const int g[3] = {static_cast<int>(std::floor(p_m.x() / vs)),
                    static_cast<int>(std::floor(p_m.y() / vs)),
                    static_cast<int>(std::floor(p_m.z() / vs))};
  const Block* b = findBlock(
      {floorDiv(g[0], kBlockSide), floorDiv(g[1], kBlockSide), floorDiv(g[2], kBlockSide)});
  if (!b) return {0.0f, 0.0f};
  const int k = (g[0] - b->coord[0] * kBlockSide) +
                kBlockSide * ((g[1] - b->coord[1] * kBlockSide) +
                              kBlockSide * (g[2] - b->coord[2] * kBlockSide));
  return {b->distance[k], b->weight[k]};
}

std::vector<Eigen::Vector3f> TsdfVolume::extractSurfacePoints() const {
  const double vs = config_.voxel_size_m;
  std::vector<std::vector<Eigen::Vector3f>> per_block(blocks_.size());
#pragma omp parallel for schedule(dynamic, 8)
  for (std::ptrdiff_t i = 0; i < std::ptrdiff_t(blocks_.size()); ++i) {
    const Block& b = blocks_[i];
    for (int k = 0; k < kBlockVoxels; ++k) {
      if (!(b.weight[k] > 0.0f)) continue;
      const int x = k % kBlockSide, y = (k / kBlockSide) % kBlockSide,
                z = k / (kBlockSide * kBlockSide);
      const int g[3] = {b.coord[0] * kBlockSide + x, b.coord[1] * kBlockSide + y,
                        b.coord[2] * kBlockSide + z};
      const Eigen::Vector3d c((g[0] + 0.5) * vs, (g[1] + 0.5) * vs, (g[2] + 0.5) * vs);
      for (int axis = 0; axis < 3; ++axis) {
        Eigen::Vector3d n = c;
        n[axis] += vs;
        float dn, wn;
        const int local[3] = {x, y, z};
        if (local[axis] + 1 < kBlockSide) {
          const int kn = k + (axis == 0 ? 1 : axis == 1 ? kBlockSide : kBlockSide * kBlockSide);
          dn = b.distance[kn];
          wn = b.weight[kn];
        } else {
          std::tie(dn, wn) = voxel(n);
        }
        const float d0 = b.distance[k];
        if (!(wn > 0.0f) || (d0 > 0.0f) == (dn > 0.0f) || d0 == dn) continue;
        const double t = d0 / (d0 - dn);
        per_block[i].push_back((c + t * (n - c)).cast<float>());
      }
    }
  }
  std::vector<Eigen::Vector3f> out;
  for (const auto& v : per_block) out.insert(out.end(), v.begin(), v.end());
  return out;
}

std::size_t TsdfVolume::memoryBytes() const {
  return blocks_.size() * (sizeof(Block) + 2 * kBlockVoxels * sizeof(float)) +
         index_.size() * (sizeof(std::array<int, 3>) + sizeof(std::size_t) + 16);
}

}  // namespace fvp::host::tsdf
