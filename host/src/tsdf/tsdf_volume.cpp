#include "fvp/host/tsdf/tsdf_volume.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "fvp/accel/backend.h"
#include "fvp/accel/kernels.h"
#include "fvp/accel/sequence.h"
#include "fvp/host/map/brick_layer.h"

#include <opencv2/imgproc.hpp>

namespace fvp::host::tsdf {
namespace {

// Whether eight mask bytes are all 0, in one load: ROI masks are mostly empty.
bool noneOfEight(const std::uint8_t* mask) {
  std::uint64_t eight;
  std::memcpy(&eight, mask, sizeof eight);
  return eight == 0;
}

map::GridGeometry boundedGrid(double voxel_size_m, const Eigen::AlignedBox3d& bounds_m) {
  if (bounds_m.isEmpty() || !bounds_m.min().allFinite() || !bounds_m.max().allFinite())
    throw std::invalid_argument("TsdfVolume: the bounds must be a finite, non-empty box");
  map::GridGeometry g;
  g.voxel_size_m = voxel_size_m;
  for (int a = 0; a < 3; ++a) {
    const auto lo = static_cast<std::int64_t>(std::floor(bounds_m.min()[a] / voxel_size_m));
    const auto hi = static_cast<std::int64_t>(std::ceil(bounds_m.max()[a] / voxel_size_m));
    const std::int64_t n =
        std::max<std::int64_t>(kBlockSide, (hi - lo + kBlockSide - 1) / kBlockSide * kBlockSide);
    if (n > 8192) throw std::invalid_argument("TsdfVolume: bounds wider than 8192 voxels");
    g.first_voxel[a] = lo;
    g.dims[a] = static_cast<int>(n);
  }
  return g;
}

/// Where a depth image meets the grid: the camera, and the grid's origin and brick size.
struct DepthView {
  const cv::Mat& depth_m;
  const cv::Mat& roi_mask;
  const StereoIntrinsics& in;
  const Eigen::Isometry3d& T_world_camera;
  Eigen::Vector3d grid_origin_m;
  double brick_m = 0.0;
};

// The bricks of the truncation band around every ROI point (along its ray), in brick order
// as a scan of the grid gives it. The fruitlets cover a few % of the image: skip the mask's
// empty runs eight pixels at a time (faster than cv::boundingRect's own pass over the mask).
// `flags`: one per brick of the grid, all 0 (and left so).
std::vector<int> truncationBandBricks(const DepthView& view, double trunc,
                                      const map::BrickLayer& layer,
                                      std::vector<std::uint8_t>& flags, TsdfIntegrateStats& stats) {
  const accel::BrickedGridParams& bp = layer.params();
  const cv::Mat& depth_m = view.depth_m;
  const cv::Mat& roi_mask = view.roi_mask;
  const StereoIntrinsics& in = view.in;
  std::vector<int> band;
  const Eigen::Vector3d eye = view.T_world_camera.translation();
  const int steps = static_cast<int>(std::ceil(2.0 * trunc / (0.5 * view.brick_m))) + 1;
  for (int v = 0; v < roi_mask.rows; ++v) {
    const float* z = depth_m.ptr<float>(v);
    const std::uint8_t* m = roi_mask.ptr<std::uint8_t>(v);
    for (int u = 0; u < roi_mask.cols; ++u) {
      if (u + 8 <= roi_mask.cols && noneOfEight(m + u)) {
        u += 7;
        continue;
      }
      if (!m[u] || !(z[u] > 0.0f) || !std::isfinite(z[u])) continue;
      ++stats.roi_pixels;
      const Eigen::Vector3d ray_camera((u - in.cx_px) / in.fx_px, (v - in.cy_px) / in.fy_px, 1.0);
      const Eigen::Vector3d p = view.T_world_camera * (z[u] * ray_camera);
      const Eigen::Vector3d dir = (p - eye).normalized();
      for (int s = 0; s <= steps; ++s) {
        const Eigen::Vector3d q =
            (p + (-trunc + 2.0 * trunc * s / steps) * dir - view.grid_origin_m) / view.brick_m;
        const double b[3] = {std::floor(q.x()), std::floor(q.y()), std::floor(q.z())};
        if (b[0] < 0 || b[1] < 0 || b[2] < 0 || b[0] >= bp.bricks_x || b[1] >= bp.bricks_y ||
            b[2] >= bp.bricks_z)
          continue;
        const int id = layer.brickIndex(int(b[0]), int(b[1]), int(b[2]));
        if (!flags[id]) {
          flags[id] = 1;
          band.push_back(id);
        }
      }
    }
  }
  for (int id : band) flags[id] = 0;
  std::sort(band.begin(), band.end());
  return band;
}

/// A box of pixels, inclusive.
struct PixelBox {
  int u_min = 0, u_max = 0, v_min = 0, v_max = 0;
  int width() const { return u_max - u_min + 1; }
  int height() const { return v_max - v_min + 1; }
};

// The pixels a voxel of the band's bricks can project to: the box of the bricks' projected
// corners (a brick is convex and in front of the camera, so its voxel centres project
// inside), rounded as the kernel rounds, clamped to the image; the whole image when a corner
// is not in front of the camera.
PixelBox bandPixelBox(const DepthView& view, const std::vector<int>& band,
                      const accel::BrickedGridParams& bp) {
  const cv::Mat& depth_m = view.depth_m;
  const StereoIntrinsics& in = view.in;
  PixelBox box{0, depth_m.cols - 1, 0, depth_m.rows - 1};
  const Eigen::Isometry3d T_camera_world = view.T_world_camera.inverse();
  double lo_u = std::numeric_limits<double>::infinity(), hi_u = -lo_u, lo_v = lo_u, hi_v = -lo_u;
  bool in_front = true;
  for (int id : band) {
    const int bx = id % bp.bricks_x, by = (id / bp.bricks_x) % bp.bricks_y,
              bz = id / (bp.bricks_x * bp.bricks_y);
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d c =
          T_camera_world *
          (view.grid_origin_m + view.brick_m * Eigen::Vector3d(bx + (corner & 1),
                                                               by + ((corner >> 1) & 1),
                                                               bz + (corner >> 2)));
      if (!(c.z() > 0.0)) in_front = false;
      const double u = in.fx_px * c.x() / c.z() + in.cx_px, v = in.fy_px * c.y() / c.z() + in.cy_px;
      lo_u = std::min(lo_u, u), hi_u = std::max(hi_u, u);
      lo_v = std::min(lo_v, v), hi_v = std::max(hi_v, v);
    }
  }
  if (in_front) {  // else: keep the whole image
    const auto pixel = [](double x, int size) {
      return int(std::clamp(std::floor(x + 0.5), 0.0, double(size - 1)));
    };
    box.u_min = pixel(lo_u - 1.0, depth_m.cols), box.u_max = pixel(hi_u + 1.0, depth_m.cols);
    box.v_min = pixel(lo_v - 1.0, depth_m.rows), box.v_max = pixel(hi_v + 1.0, depth_m.rows);
  }
  return box;
}

// The ROI depth over the box, 0 where a pixel is not ROI or has no depth.
std::vector<float> croppedRoiDepth(const cv::Mat& depth_m, const cv::Mat& roi_mask,
                                   const PixelBox& box) {
  const int width = box.width(), height = box.height();
  std::vector<float> crop(std::size_t(width) * height, 0.0f);
  for (int v = 0; v < height; ++v) {
    const float* z = depth_m.ptr<float>(v + box.v_min) + box.u_min;
    const std::uint8_t* m = roi_mask.ptr<std::uint8_t>(v + box.v_min) + box.u_min;
    for (int u = 0; u < width; ++u) {
      if (u + 8 <= width && noneOfEight(m + u)) {
        u += 7;
        continue;
      }
      if (m[u] && z[u] > 0.0f && std::isfinite(z[u])) crop[std::size_t(v) * width + u] = z[u];
    }
  }
  return crop;
}

}  // namespace

void TsdfConfig::validate() const {
  if (!(voxel_size_m > 1e-5 && voxel_size_m < 0.1))
    throw std::invalid_argument("tsdf config: voxel_size_m: expected (1e-5, 0.1) m");
  if (!(truncation_m >= voxel_size_m && truncation_m < 1.0))
    throw std::invalid_argument("tsdf config: truncation_m: expected [voxel_size_m, 1) m");
  if (!(max_weight > 0.0f)) throw std::invalid_argument("tsdf config: max_weight: expected > 0");
}

TsdfVolume::TsdfVolume(const TsdfConfig& config, const Eigen::AlignedBox3d& bounds_m,
                       accel::Backend* backend)
    : config_(config), backend_(backend) {
  config_.validate();
  geometry_ = boundedGrid(config_.voxel_size_m, bounds_m);
  if (!backend_) {
    own_backend_ = accel::createBackend(accel::BackendKind::kCpu);
    backend_ = own_backend_.get();
  }
  layer_ = std::make_unique<map::BrickLayer>(*backend_, geometry_, std::nullopt,
                                             map::BrickAllocation::kOnTouch);
  distance_channel_ = layer_->addChannel("tsdf_distance", sizeof(float), 0u);
  weight_channel_ = layer_->addChannel("tsdf_weight", sizeof(float), 0u);
}

TsdfVolume::~TsdfVolume() = default;

std::size_t TsdfVolume::blockCount() const {
  return layer_->allocatedBricks();
}

std::size_t TsdfVolume::memoryBytes() const {
  return layer_->deviceBytes();
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
        "TsdfVolume::integrate: expected CV_32F depth and CV_8U mask of one size");
  const auto start = std::chrono::steady_clock::now();
  TsdfIntegrateStats stats;
  const double vs = config_.voxel_size_m, trunc = config_.truncation_m;
  const DepthView view{
      depth_m,
      roi_mask,
      in,
      T_world_camera,
      vs * Eigen::Vector3d(double(geometry_.first_voxel[0]), double(geometry_.first_voxel[1]),
                           double(geometry_.first_voxel[2])),
      vs * kBlockSide};

  // 1. The bricks of the truncation band around every ROI point.
  band_flags_.resize(layer_->gridBricks(), 0);
  const std::vector<int> band = truncationBandBricks(view, trunc, *layer_, band_flags_, stats);
  if (band.empty()) {
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return stats;
  }
  const std::size_t before = layer_->allocatedBricks();
  layer_->allocate(band);
  stats.blocks_allocated = layer_->allocatedBricks() - before;
  std::vector<std::uint32_t> update;
  update.reserve(band.size());
  for (int id : band)
    update.push_back(static_cast<std::uint32_t>(layer_->table()[id] & FVP_BRICK_INDEX_MASK));
  stats.blocks_updated = update.size();
  stats.voxels_updated = update.size() * kBlockVoxels;

  // 2. The ROI depth over the pixels a voxel of the band's bricks can project to. The result
  // equals integrating the whole image; fruit outside the Cluster Region no longer widens the
  // upload.
  const PixelBox box = bandPixelBox(view, band, layer_->params());
  const std::vector<float> crop = croppedRoiDepth(depth_m, roi_mask, box);
  stats.depth_pixels_uploaded = crop.size();

  // 3. The kernel over every voxel of the band's bricks.
  accel::TsdfParams params{};
  Eigen::Isometry3d T_world_grid = Eigen::Isometry3d::Identity();
  T_world_grid.translation() = view.grid_origin_m;
  const Eigen::Matrix<double, 3, 4> T_camera_grid =
      (T_world_camera.inverse() * T_world_grid).matrix().topRows<3>();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) params.camera_from_grid[4 * r + c] = float(T_camera_grid(r, c));
  params.voxel_size_m = float(vs);
  params.truncation_m = float(trunc);
  params.max_weight = config_.max_weight;
  params.fx_px = float(in.fx_px);
  params.fy_px = float(in.fy_px);
  params.cx_px = float(in.cx_px - box.u_min);
  params.cy_px = float(in.cy_px - box.v_min);
  params.width_px = box.width();
  params.height_px = box.height();
  params.update_bricks = static_cast<std::uint32_t>(update.size());
  params.allocated_bricks = static_cast<std::uint32_t>(layer_->allocatedBricks());
  const auto update_buf = backend_->createBuffer(update.size() * sizeof(update[0]));
  const auto depth_buf = backend_->createBuffer(crop.size() * sizeof(crop[0]));
  accel::Sequence(*backend_)
      .upload(*update_buf, update.data(), update.size() * sizeof(update[0]))
      .upload(*depth_buf, crop.data(), crop.size() * sizeof(crop[0]))
      .run(accel::kernels::tsdfIntegrate(), params,
           {&layer_->coordsBuffer(), update_buf.get(), depth_buf.get(),
            &layer_->channel(distance_channel_), &layer_->channel(weight_channel_)})
      .eval();
  layer_->markChanged(update);
  host_stale_ = true;
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

void TsdfVolume::syncHost() const {
  if (!host_stale_ && host_distance_.size() == layer_->slotCount()) return;
  const std::size_t n = layer_->slotCount();
  host_distance_.assign(n, 0.0f);
  host_weight_.assign(n, 0.0f);
  if (n) {
    accel::Sequence(*backend_)
        .download(layer_->channel(distance_channel_), host_distance_.data(), n * sizeof(float))
        .download(layer_->channel(weight_channel_), host_weight_.data(), n * sizeof(float))
        .eval();
  }
  host_stale_ = false;
}

const std::vector<float>& TsdfVolume::distances() const {
  syncHost();
  return host_distance_;
}

const std::vector<float>& TsdfVolume::weights() const {
  syncHost();
  return host_weight_;
}

std::pair<float, float> TsdfVolume::voxel(const Eigen::Vector3d& p_m) const {
  std::array<int, 3> index;
  if (!geometry_.gridIndex(p_m, index)) return {0.0f, 0.0f};
  const std::int64_t slot = layer_->slotOf(index);
  if (slot < 0) return {0.0f, 0.0f};
  syncHost();
  return {host_distance_[slot], host_weight_[slot]};
}

std::vector<Eigen::Vector3f> TsdfVolume::extractSurfacePoints() const {
  syncHost();
  const std::size_t bricks = layer_->allocatedBricks();
  std::vector<std::vector<Eigen::Vector3f>> per_brick(bricks);
#pragma omp parallel for schedule(dynamic, 8)
  for (std::ptrdiff_t b = 0; b < std::ptrdiff_t(bricks); ++b) {
    for (int k = 0; k < kBlockVoxels; ++k) {
      const std::size_t slot = std::size_t(b) * kBlockVoxels + k;
      if (!(host_weight_[slot] > 0.0f)) continue;
      const float d0 = host_distance_[slot];
      // In-brick neighbours are the next slots (x fastest); only the brick's far faces look
      // their neighbour up in the table.
      const std::array<int, 3> local = {k & 7, (k >> 3) & 7, k >> 6};
      for (int axis = 0; axis < 3; ++axis) {
        std::int64_t ns;
        if (local[axis] + 1 < kBlockSide) {
          ns = std::int64_t(slot) + (std::int64_t{1} << (3 * axis));
        } else {
          std::array<int, 3> n = layer_->voxelOfSlot(slot);
          ++n[axis];
          ns = layer_->slotOf(n);
          if (ns < 0) continue;
        }
        const float dn = host_distance_[ns];
        if (!(host_weight_[ns] > 0.0f) || (d0 > 0.0f) == (dn > 0.0f) || d0 == dn) continue;
        const double t = d0 / (d0 - dn);
        Eigen::Vector3d p = geometry_.voxelCenter_m(layer_->voxelOfSlot(slot));
        p[axis] += t * config_.voxel_size_m;
        per_brick[b].push_back(p.cast<float>());
      }
    }
  }
  std::vector<Eigen::Vector3f> out;
  for (const auto& v : per_brick) out.insert(out.end(), v.begin(), v.end());
  return out;
}

TriangleMesh TsdfVolume::extractMesh() const {
  syncHost();
  std::vector<std::array<int, 3>> cubes;
  for (std::size_t slot = 0; slot < host_weight_.size(); ++slot)
    if (host_weight_[slot] > 0.0f) cubes.push_back(layer_->voxelOfSlot(slot));
  const auto sample = [this](const std::array<int, 3>& index, float& distance) {
    const std::int64_t slot = layer_->slotOf(index);
    if (slot < 0 || !(host_weight_[slot] > 0.0f)) return false;
    distance = host_distance_[slot];
    return true;
  };
  return MarchingCubes::extract(cubes, sample, geometry_.voxelCenter_m({0, 0, 0}),
                                config_.voxel_size_m);
}

}  // namespace fvp::host::tsdf
