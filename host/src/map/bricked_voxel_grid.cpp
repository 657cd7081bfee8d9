#include "fvp/host/map/bricked_voxel_grid.h"

#include "fvp/accel/kernels.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <tuple>

namespace fvp::host::map {
namespace {

constexpr float kUnknown = std::numeric_limits<float>::quiet_NaN();

template <typename T>
void uploadVector(accel::Backend& backend, accel::DeviceBuffer& buf, const std::vector<T>& v,
                  std::size_t offset_elements = 0) {
  if (!v.empty()) backend.upload(buf, v.data(), v.size() * sizeof(T), offset_elements * sizeof(T));
}

}  // namespace

BrickedVoxelGrid::BrickedVoxelGrid(accel::Backend& backend, const GridGeometry& geometry,
                                   bool with_roi, std::optional<fvp_region> region,
                                   Allocation allocation)
    : backend_(backend), geometry_(geometry), with_roi_(with_roi), allocation_(allocation) {
  params_.grid = geometry.params();
  params_.bricks_x = geometry.dims[0] / accel::kBrickEdge;
  params_.bricks_y = geometry.dims[1] / accel::kBrickEdge;
  params_.bricks_z = geometry.dims[2] / accel::kBrickEdge;
  params_.use_region = region.has_value();
  if (region) params_.region = *region;
  const std::size_t brick_count =
      static_cast<std::size_t>(params_.bricks_x) * params_.bricks_y * params_.bricks_z;
  table_.assign(brick_count, accel::kNoBrick);
  table_buf_ = backend_.createBuffer(brick_count * sizeof(int));
  missing_ = backend_.createBufferFrom(std::vector<std::uint32_t>(brick_count + 1, 0));
  counter_ = backend_.createBuffer(sizeof(std::uint32_t));
  ensurePoolCapacity(0);
  if (allocation == Allocation::kUpFront) {
    // Every brick of the box, also those outside the region: the separable distance passes
    // carry values through voxels between two region voxels that may lie outside it.
    std::vector<int> ids(brick_count);
    for (std::size_t id = 0; id < brick_count; ++id) ids[id] = static_cast<int>(id);
    allocate(ids);
  } else {
    uploadTables();
  }
}

BrickedVoxelGrid::~BrickedVoxelGrid() = default;

std::size_t BrickedVoxelGrid::deviceBytes() const {
  std::size_t bytes = table_.size() * sizeof(int) * 2 + brick_coords_.capacity() * sizeof(int);
  bytes += pool_bricks_ * accel::kBrickVoxels * sizeof(float) * (with_roi_ ? 2 : 1);
  bytes += pool_bricks_ * accel::kBrickVoxels;  // marks: one byte lane per slot
  if (distance_) bytes += distance_->sizeBytes();
  return bytes;
}

bool BrickedVoxelGrid::brickInsideRegion(int bx, int by, int bz) const {
  if (!params_.use_region) return false;
  // Farthest voxel centre of the brick; the margin keeps the kernels' float test on every
  // voxel of a flagged brick true.
  const float c[3] = {params_.region.center_x_vox, params_.region.center_y_vox,
                      params_.region.center_z_vox};
  const int b[3] = {bx, by, bz};
  double d2 = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double d = std::max(std::abs(b[a] * 8 + 0.5 - c[a]), std::abs(b[a] * 8 + 7.5 - c[a]));
    d2 += d * d;
  }
  const double r = std::sqrt(params_.region.radius_sq_vox) - 0.01;
  return r > 0 && d2 < r * r;
}

void BrickedVoxelGrid::ensurePoolCapacity(std::size_t bricks) {
  if (occupancy_ && bricks <= pool_bricks_) return;
  // Kernels index slots with 32-bit ints: brick * 512 + local must stay below 2^31.
  if (bricks > kMaxBricks) {
    throw std::length_error("voxel map: " + std::to_string(bricks) +
                            " bricks of 512 voxels needed, at most " + std::to_string(kMaxBricks) +
                            " fit the kernels' 32-bit slot indices; "
                            "use a coarser voxel size or a smaller box");
  }
  // Grow geometrically; keep what is there (download, then upload into the new pools).
  const std::size_t capacity =
      std::min(std::max<std::size_t>({bricks, pool_bricks_ * 2, 8}), kMaxBricks);
  const std::size_t old_slots = allocatedBricks() * accel::kBrickVoxels;
  const std::size_t slots = capacity * accel::kBrickVoxels;
  std::vector<float> occ(slots, kUnknown), roi(with_roi_ ? slots : 1, kUnknown);
  if (occupancy_ && old_slots) {
    backend_.download(*occupancy_, occ.data(), old_slots * sizeof(float));
    if (with_roi_) backend_.download(*roi_, roi.data(), old_slots * sizeof(float));
  }
  occupancy_ = backend_.createBufferFrom(occ);
  roi_ = backend_.createBufferFrom(roi);
  // Marks are all zero between scans, so new ones start zeroed.
  marks_ = backend_.createBufferFrom(std::vector<std::uint32_t>(slots / 4, 0u));
  pool_bricks_ = capacity;
  distance_.reset();
}

void BrickedVoxelGrid::uploadTables() {
  uploadVector(backend_, *table_buf_, table_);
  coords_buf_ =
      backend_.createBufferFrom(brick_coords_.empty() ? std::vector<int>(3, 0) : brick_coords_);
}

void BrickedVoxelGrid::allocate(const std::vector<int>& brick_ids) {
  if (brick_ids.empty()) return;
  ensurePoolCapacity(allocatedBricks() + brick_ids.size());
  for (int id : brick_ids) {
    if (table_[id] != accel::kNoBrick) continue;
    const int bx = id % params_.bricks_x;
    const int by = (id / params_.bricks_x) % params_.bricks_y;
    const int bz = id / (params_.bricks_x * params_.bricks_y);
    table_[id] = static_cast<int>(allocatedBricks()) |
                 (brickInsideRegion(bx, by, bz) ? FVP_BRICK_INSIDE : 0);
    brick_coords_.insert(brick_coords_.end(), {bx, by, bz});
  }
  uploadTables();
  host_stale_ = true;
  distance_.reset();  // computed for the old brick set
}

std::size_t BrickedVoxelGrid::integrate(accel::DeviceBuffer& points, std::uint32_t point_count,
                                        const Eigen::Vector3f& sensor_m,
                                        const OccupancyModel& model) {
  accel::ScanParams scan{};
  scan.map = params_;
  scan.sensor_x_m = sensor_m.x();
  scan.sensor_y_m = sensor_m.y();
  scan.sensor_z_m = sensor_m.z();
  scan.point_count = point_count;
  scan.brick_count = static_cast<int>(table_.size());
  const auto brick_count = static_cast<std::uint32_t>(table_.size());
  for (int attempt = 0;; ++attempt) {
    scan.slot_count = static_cast<std::uint32_t>(pool_bricks_ * accel::kBrickVoxels);
    backend_.run(accel::kernels::scanMark(), scan,
                 {&points, table_buf_.get(), marks_.get(), missing_.get()});
    if (allocation_ == Allocation::kUpFront) break;
    std::uint32_t any_missing = 0;
    backend_.download(*missing_, &any_missing, sizeof(any_missing),
                      brick_count * sizeof(std::uint32_t));
    if (!any_missing) break;
    if (attempt > 0)
      throw std::logic_error("BrickedVoxelGrid: bricks still missing after allocation");
    // Allocate every brick the rays reached, in ascending order (the same on every
    // backend), then mark again: marks are idempotent.
    std::vector<std::uint32_t> flags(brick_count + 1);
    backend_.download(*missing_, flags.data(), flags.size() * sizeof(std::uint32_t));
    std::vector<int> ids;
    for (std::uint32_t b = 0; b < brick_count; ++b)
      if (flags[b]) ids.push_back(static_cast<int>(b));
    allocate(ids);
    std::fill(flags.begin(), flags.end(), 0u);
    uploadVector(backend_, *missing_, flags);
    // Mark again: the new bricks' voxels were skipped, and grown pools start unmarked.
  }
  accel::UpdateParams update{};
  update.slot_count = static_cast<std::uint32_t>(pool_bricks_ * accel::kBrickVoxels);
  update.hit_logodds = model.hitLogOdds();
  update.miss_logodds = model.missLogOdds();
  update.clamp_min_logodds = model.clampMinLogOdds();
  update.clamp_max_logodds = model.clampMaxLogOdds();
  update.has_roi = with_roi_;
  const std::uint32_t zero = 0;
  backend_.upload(*counter_, &zero, sizeof(zero));
  backend_.run(accel::kernels::scanUpdate(), update,
               {marks_.get(), occupancy_.get(), with_roi_ ? roi_.get() : nullptr, counter_.get()});
  std::uint32_t updated = 0;
  backend_.download(*counter_, &updated, sizeof(updated));
  host_stale_ = true;
  distance_.reset();  // the ROI changed: recompute on request
  return updated;
}

void BrickedVoxelGrid::refreshHostCopy() const {
  // Const queries may come from several threads; the first one refreshes the mirror.
  std::lock_guard<std::mutex> lock(host_mutex_);
  if (!host_stale_) return;
  const std::size_t slots = slotCount();
  host_occupancy_.resize(slots);
  host_roi_.resize(with_roi_ ? slots : 0);
  if (slots) {
    backend_.download(*occupancy_, host_occupancy_.data(), slots * sizeof(float));
    if (with_roi_) backend_.download(*roi_, host_roi_.data(), slots * sizeof(float));
  }
  host_stale_ = false;
}

std::int64_t BrickedVoxelGrid::slotOf(const std::array<int, 3>& index) const {
  for (int a = 0; a < 3; ++a)
    if (index[a] < 0 || index[a] >= geometry_.dims[a]) return -1;
  const int entry = table_[brickIndex(index[0] >> 3, index[1] >> 3, index[2] >> 3)];
  if (entry == accel::kNoBrick) return -1;
  return std::int64_t{entry & FVP_BRICK_INDEX_MASK} * accel::kBrickVoxels + (index[0] & 7) +
         8 * ((index[1] & 7) + 8 * (index[2] & 7));
}

float BrickedVoxelGrid::occupancyAt(const std::array<int, 3>& index) const {
  const std::int64_t slot = slotOf(index);
  if (slot < 0) return kUnknown;
  refreshHostCopy();
  return host_occupancy_[slot];
}

float BrickedVoxelGrid::roiAt(const std::array<int, 3>& index) const {
  const std::int64_t slot = slotOf(index);
  if (slot < 0 || !with_roi_) return kUnknown;
  refreshHostCopy();
  return host_roi_[slot];
}

void BrickedVoxelGrid::assignDense(const std::vector<float>& occupancy,
                                   const std::vector<float>& roi) {
  const auto voxels = static_cast<std::size_t>(geometry_.voxelCount());
  if (occupancy.size() != voxels || (with_roi_ && roi.size() != voxels))
    throw std::invalid_argument(
        "BrickedVoxelGrid::assignDense: arrays must hold one value per grid voxel");
  std::vector<int> all;
  for (std::size_t id = 0; id < table_.size(); ++id) all.push_back(static_cast<int>(id));
  allocate(all);
  const std::size_t slots = slotCount();
  std::vector<float> occ(slots, kUnknown), roi_pool(with_roi_ ? slots : 0, kUnknown);
  for (int z = 0; z < geometry_.dims[2]; ++z)
    for (int y = 0; y < geometry_.dims[1]; ++y)
      for (int x = 0; x < geometry_.dims[0]; ++x) {
        const std::size_t dense =
            x + geometry_.dims[0] * (y + static_cast<std::size_t>(geometry_.dims[1]) * z);
        const auto slot = static_cast<std::size_t>(slotOf({x, y, z}));
        occ[slot] = occupancy[dense];
        if (with_roi_) roi_pool[slot] = roi[dense];
      }
  uploadVector(backend_, *occupancy_, occ);
  if (with_roi_) uploadVector(backend_, *roi_, roi_pool);
  host_stale_ = true;
}

void BrickedVoxelGrid::allocateRoiHalo(int radius_vox) {
  // The passes need every voxel within radius_vox (Chebyshev) of an ROI voxel to have a
  // slot: the x pass result at (qx, py, pz) is what carries p's distance to q.
  refreshHostCopy();
  const int halo = (radius_vox + accel::kBrickEdge - 1) / accel::kBrickEdge;
  std::vector<char> wanted(table_.size(), 0);
  bool any = false;
  for (std::size_t b = 0; b < allocatedBricks(); ++b) {
    bool has_roi = false;
    for (int local = 0; local < accel::kBrickVoxels && !has_roi; ++local)
      has_roi = host_roi_[b * accel::kBrickVoxels + local] > 0.0f;
    if (!has_roi) continue;
    const int* c = &brick_coords_[3 * b];
    for (int z = std::max(0, c[2] - halo); z <= std::min(params_.bricks_z - 1, c[2] + halo); ++z)
      for (int y = std::max(0, c[1] - halo); y <= std::min(params_.bricks_y - 1, c[1] + halo); ++y)
        for (int x = std::max(0, c[0] - halo); x <= std::min(params_.bricks_x - 1, c[0] + halo);
             ++x) {
          const int id = brickIndex(x, y, z);
          if (table_[id] == accel::kNoBrick) wanted[id] = any = true;
        }
  }
  if (!any) return;
  std::vector<int> ids;
  for (std::size_t id = 0; id < wanted.size(); ++id)
    if (wanted[id]) ids.push_back(static_cast<int>(id));
  allocate(ids);
}

void BrickedVoxelGrid::computeRoiDistance(int radius_vox) {
  if (!with_roi_) throw std::logic_error("computeRoiDistance needs a map with ROI");
  if (allocation_ == Allocation::kOnTouch) allocateRoiHalo(radius_vox);
  const std::size_t slots = slotCount();
  accel::EdtParams edt{};
  edt.map = params_;
  edt.radius_vox = radius_vox;
  edt.slot_count = static_cast<std::uint32_t>(slots);
  auto sq_a = backend_.createBuffer(std::max<std::size_t>(slots, 1) * sizeof(std::uint32_t));
  auto sq_b = backend_.createBuffer(std::max<std::size_t>(slots, 1) * sizeof(std::uint32_t));
  distance_ = backend_.createBuffer(std::max<std::size_t>(slots, 1) * sizeof(float));
  // x pass: roi -> sq_a; y pass: sq_a -> sq_b; z pass: sq_b -> distance.
  const auto kernel = accel::kernels::roiDistance();
  edt.axis = 0;
  backend_.run(kernel, edt,
               {coords_buf_.get(), table_buf_.get(), roi_.get(), nullptr, sq_a.get(), nullptr});
  edt.axis = 1;
  backend_.run(kernel, edt,
               {coords_buf_.get(), table_buf_.get(), nullptr, sq_a.get(), sq_b.get(), nullptr});
  edt.axis = 2;
  backend_.run(
      kernel, edt,
      {coords_buf_.get(), table_buf_.get(), nullptr, sq_b.get(), nullptr, distance_.get()});
  distance_radius_vox_ = radius_vox;
  std::lock_guard<std::mutex> lock(host_mutex_);
  host_distance_.clear();  // downloaded on the first query
}

float BrickedVoxelGrid::roiDistanceVoxAt(const std::array<int, 3>& index) const {
  if (!distance_) throw std::logic_error("roiDistanceVoxAt: call computeRoiDistance() first");
  const std::int64_t slot = slotOf(index);
  if (slot < 0) return static_cast<float>(distance_radius_vox_);
  std::lock_guard<std::mutex> lock(host_mutex_);
  if (host_distance_.empty()) {
    host_distance_.resize(std::max<std::size_t>(slotCount(), 1));
    if (slotCount())
      backend_.download(*distance_, host_distance_.data(), slotCount() * sizeof(float));
  }
  return host_distance_[static_cast<std::size_t>(slot)];
}

std::vector<float> BrickedVoxelGrid::roiDistanceVox(int radius_vox) {
  computeRoiDistance(radius_vox);
  std::vector<float> dense(static_cast<std::size_t>(geometry_.voxelCount()));
  std::size_t i = 0;
  for (int z = 0; z < geometry_.dims[2]; ++z)
    for (int y = 0; y < geometry_.dims[1]; ++y)
      for (int x = 0; x < geometry_.dims[0]; ++x) dense[i++] = roiDistanceVoxAt({x, y, z});
  return dense;
}

std::vector<FrontierVoxel> BrickedVoxelGrid::extractFrontiers(float occupied_logodds) {
  if (!with_roi_) throw std::logic_error("extractFrontiers needs a map with ROI");
  accel::FrontierParams params{};
  params.map = params_;
  params.occupied_logodds = occupied_logodds;
  params.slot_count = static_cast<std::uint32_t>(slotCount());
  std::uint32_t capacity = 4096;
  std::vector<accel::Frontier> raw;
  for (;;) {
    params.capacity = capacity;
    auto out = backend_.createBuffer(std::size_t{capacity} * sizeof(accel::Frontier));
    const std::uint32_t zero = 0;
    backend_.upload(*counter_, &zero, sizeof(zero));
    backend_.run(accel::kernels::frontier(), params,
                 {coords_buf_.get(), table_buf_.get(), occupancy_.get(), roi_.get(), out.get(),
                  counter_.get()});
    std::uint32_t found = 0;
    backend_.download(*counter_, &found, sizeof(found));
    if (found <= capacity) {
      raw.resize(found);
      if (found) backend_.download(*out, raw.data(), found * sizeof(accel::Frontier));
      break;
    }
    capacity = found;  // too small: run again with room for all
  }
  // Kernels append in any order: sort by grid index for a deterministic result.
  std::sort(raw.begin(), raw.end(), [](const accel::Frontier& a, const accel::Frontier& b) {
    return std::tie(a.z, a.y, a.x) < std::tie(b.z, b.y, b.x);
  });
  std::vector<FrontierVoxel> frontiers;
  frontiers.reserve(raw.size());
  for (const auto& f : raw) {
    FrontierVoxel v;
    v.index = {f.x, f.y, f.z};
    v.center_m = geometry_.voxelCenter_m(v.index);
    v.roi_frontier = (f.flags & FVP_FRONTIER_ROI) != 0;
    v.exploration_frontier = (f.flags & FVP_FRONTIER_EXPLORE) != 0;
    const Eigen::Vector3d n(f.normal_x, f.normal_y, f.normal_z);
    if (n.squaredNorm() > 0) v.normal = n.normalized();
    frontiers.push_back(v);
  }
  return frontiers;
}

}  // namespace fvp::host::map
