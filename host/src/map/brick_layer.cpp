#include "fvp/host/map/brick_layer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace fvp::host::map {

BrickLayer::BrickLayer(accel::Backend& backend, const GridGeometry& geometry,
                       std::optional<fvp_region> region, BrickAllocation allocation)
    : backend_(backend), geometry_(geometry), allocation_(allocation) {
  params_.grid = geometry.params();
  params_.bricks_x = geometry.dims[0] / accel::kBrickEdge;
  params_.bricks_y = geometry.dims[1] / accel::kBrickEdge;
  params_.bricks_z = geometry.dims[2] / accel::kBrickEdge;
  params_.use_region = region.has_value();
  if (region) params_.region = *region;
  accel::checkBrickedGrid(params_, "BrickLayer");
  table_.assign(accel::brickCount(params_), accel::kNoBrick);
  table_buf_ = backend_.createBuffer(table_.size() * sizeof(int));
  ensureCapacity(0);
  if (allocation == BrickAllocation::kUpFront)
    allocateAll();
  else
    uploadTables();
}

BrickLayer::~BrickLayer() = default;

std::size_t BrickLayer::deviceBytes() const {
  std::size_t bytes = table_buf_->sizeBytes() + (coords_buf_ ? coords_buf_->sizeBytes() : 0);
  for (const Channel& c : channels_) bytes += c.buffer->sizeBytes();
  return bytes;
}

BrickLayer::ChannelId BrickLayer::addChannel(std::string name, std::size_t bytes_per_slot,
                                             std::uint32_t fill_bits) {
  if (bytes_per_slot != 1 && bytes_per_slot != 2 && bytes_per_slot != 4 && bytes_per_slot != 8)
    throw std::invalid_argument("BrickLayer::addChannel: " + name +
                                ": bytes_per_slot must be 1, 2, 4 or 8");
  Channel c{std::move(name), bytes_per_slot, fill_bits, nullptr};
  c.buffer = makeChannelBuffer(c, capacitySlots(), nullptr, 0);
  channels_.push_back(std::move(c));
  return channels_.size() - 1;
}

std::unique_ptr<accel::DeviceBuffer> BrickLayer::makeChannelBuffer(const Channel& c,
                                                                   std::size_t slots,
                                                                   const accel::DeviceBuffer* old,
                                                                   std::size_t old_slots) {
  // Whole 32-bit words, so that byte channels read as uint words by the kernels fit.
  const std::size_t bytes = std::max<std::size_t>((slots * c.bytes_per_slot + 3) / 4 * 4, 4);
  std::vector<std::uint32_t> host(bytes / 4, c.fill_bits);
  if (old && old_slots)
    backend_.download(*old, host.data(), std::min(old_slots * c.bytes_per_slot, old->sizeBytes()));
  return backend_.createBufferFrom(host);
}

bool BrickLayer::brickInsideRegion(int bx, int by, int bz) const {
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

void BrickLayer::ensureCapacity(std::size_t bricks) {
  if (capacity_bricks_ && bricks <= capacity_bricks_) return;
  if (bricks > kMaxBricks) {
    throw std::length_error("voxel map: " + std::to_string(bricks) +
                            " bricks of 512 voxels needed, at most " + std::to_string(kMaxBricks) +
                            " fit the kernels' 32-bit slot indices; use a coarser voxel size or a "
                            "smaller box");
  }
  // Grow geometrically; every channel keeps what it holds.
  const std::size_t capacity =
      std::min(std::max<std::size_t>({bricks, capacity_bricks_ * 2, 8}), kMaxBricks);
  const std::size_t old_slots = slotCount();
  for (Channel& c : channels_)
    c.buffer = makeChannelBuffer(c, capacity * accel::kBrickVoxels, c.buffer.get(), old_slots);
  capacity_bricks_ = capacity;
}

void BrickLayer::uploadTables() {
  backend_.upload(*table_buf_, table_.data(), table_.size() * sizeof(int));
  coords_buf_ =
      backend_.createBufferFrom(brick_coords_.empty() ? std::vector<int>(3, 0) : brick_coords_);
}

void BrickLayer::allocate(const std::vector<int>& brick_ids) {
  std::size_t added = 0;
  for (int id : brick_ids) added += table_.at(id) == accel::kNoBrick;
  if (!added) return;
  ensureCapacity(allocatedBricks() + added);
  for (int id : brick_ids) {
    if (table_[id] != accel::kNoBrick) continue;
    const int bx = id % params_.bricks_x;
    const int by = (id / params_.bricks_x) % params_.bricks_y;
    const int bz = id / (params_.bricks_x * params_.bricks_y);
    table_[id] = static_cast<int>(allocatedBricks()) |
                 (brickInsideRegion(bx, by, bz) ? FVP_BRICK_INSIDE : 0);
    brick_coords_.insert(brick_coords_.end(), {bx, by, bz});
    brick_stamps_.push_back(change_count_);
  }
  uploadTables();
  ++layout_version_;
}

void BrickLayer::allocateAll() {
  std::vector<int> ids(table_.size());
  for (std::size_t id = 0; id < ids.size(); ++id) ids[id] = static_cast<int>(id);
  allocate(ids);
}

std::int64_t BrickLayer::slotOf(const std::array<int, 3>& index) const {
  for (int a = 0; a < 3; ++a)
    if (index[a] < 0 || index[a] >= geometry_.dims[a]) return -1;
  const int entry = table_[brickIndex(index[0] >> 3, index[1] >> 3, index[2] >> 3)];
  if (entry == accel::kNoBrick) return -1;
  return fvp_slot_of_entry(entry, fvp_local_of(index[0], index[1], index[2]));
}

std::array<int, 3> BrickLayer::voxelOfSlot(std::size_t slot) const {
  std::array<int, 3> v;
  fvp_slot_voxel(brick_coords_.data(), static_cast<unsigned>(slot), &v[0], &v[1], &v[2]);
  return v;
}

void BrickLayer::markChanged(const std::vector<std::uint32_t>& allocated_bricks) {
  if (allocated_bricks.empty()) return;
  ++change_count_;
  for (std::uint32_t b : allocated_bricks) brick_stamps_.at(b) = change_count_;
}

void BrickLayer::markAllChanged() {
  ++change_count_;
  std::fill(brick_stamps_.begin(), brick_stamps_.end(), change_count_);
}

}  // namespace fvp::host::map
