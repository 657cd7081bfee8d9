// Bricked storage of one voxel grid on a compute backend (nvblox's VoxelBlockLayer is the
// model): a brick table over the grid, the allocated bricks' coordinates, and any number of
// per-slot channels (occupancy, ROI, scan marks, the ROI distance; next the TSDF's distance
// and weight). Slot = allocation index * 512 + voxel index in the brick (kernels/fvp_map.h).
// Bricks of 8^3 voxels are allocated up front (small grids) or as scans reach them, so a
// 1 mm map of a whole observation box costs only what the sensor has seen. Allocation,
// pool growth (every channel keeps its contents) and change tracking are written once here;
// the operations (ScanIntegrator, RoiDistanceField, FrontierExtractor) are separate classes.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fvp/accel/backend.h"
#include "fvp/host/map/grid_geometry.h"

namespace fvp::host::map {

enum class BrickAllocation {
  kUpFront,  ///< every brick of the grid box at construction
  kOnTouch,  ///< bricks as operations ask for them (scans reaching them)
};

class BrickLayer {
 public:
  /// The most bricks one layer may allocate: kernels index slots with 32-bit ints.
  static constexpr std::size_t kMaxBricks = (std::size_t{1} << 22) - 1;
  using ChannelId = std::size_t;

  /// region: voxels outside it are never mapped (the fine map's Cluster Region). With
  /// kUpFront every brick of the box is allocated, also those outside the region: the
  /// separable distance passes carry values through voxels between two region voxels.
  BrickLayer(accel::Backend& backend, const GridGeometry& geometry,
             std::optional<fvp_region> region, BrickAllocation allocation);
  ~BrickLayer();
  BrickLayer(const BrickLayer&) = delete;
  BrickLayer& operator=(const BrickLayer&) = delete;

  accel::Backend& backend() const { return backend_; }
  const GridGeometry& geometry() const { return geometry_; }
  const accel::BrickedGridParams& params() const { return params_; }
  BrickAllocation allocation() const { return allocation_; }
  /// Bricks of the grid box (entries of the brick table).
  std::size_t gridBricks() const { return table_.size(); }
  std::size_t allocatedBricks() const { return brick_coords_.size() / 3; }
  std::size_t slotCount() const { return allocatedBricks() * accel::kBrickVoxels; }
  /// Slots every channel holds (allocation grows geometrically).
  std::size_t capacitySlots() const { return capacity_bricks_ * accel::kBrickVoxels; }
  /// Device bytes held: tables and every channel.
  std::size_t deviceBytes() const;

  /// Adds a channel of bytes_per_slot (1, 2, 4 or 8) whose new slots are filled with the
  /// 4-byte pattern fill_bits (e.g. a quiet NaN for "unknown"). Returns its id.
  ChannelId addChannel(std::string name, std::size_t bytes_per_slot, std::uint32_t fill_bits);
  accel::DeviceBuffer& channel(ChannelId id) { return *channels_.at(id).buffer; }
  const accel::DeviceBuffer& channel(ChannelId id) const { return *channels_.at(id).buffer; }

  /// Allocates the given bricks (ids into the brick table; already allocated ones are
  /// skipped) in the order given, growing every channel when needed.
  void allocate(const std::vector<int>& brick_ids);
  void allocateAll();
  /// Counts calls to allocate() that added bricks: operations whose device results are per
  /// slot compare it to know whether the layout changed under them.
  std::uint64_t layoutVersion() const { return layout_version_; }

  const std::vector<int>& table() const { return table_; }
  /// Grid coordinates (x, y, z) of each allocated brick, in allocation order.
  const std::vector<int>& brickCoords() const { return brick_coords_; }
  accel::DeviceBuffer& tableBuffer() { return *table_buf_; }
  accel::DeviceBuffer& coordsBuffer() { return *coords_buf_; }
  int brickIndex(int bx, int by, int bz) const {
    return bx + params_.bricks_x * (by + params_.bricks_y * bz);
  }
  /// Slot of a grid voxel; -1 when outside the grid or its brick is not allocated.
  std::int64_t slotOf(const std::array<int, 3>& index) const;
  /// Grid index of a slot (slot < slotCount()).
  std::array<int, 3> voxelOfSlot(std::size_t slot) const;

  /// Change tracking: operations that modify channels report the allocated bricks they
  /// changed; readers (host mirrors, Embree scenes) refresh only bricks changed after the
  /// change count they last saw.
  void markChanged(const std::vector<std::uint32_t>& allocated_bricks);
  void markAllChanged();
  std::uint64_t changeCount() const { return change_count_; }
  /// Change count at which each allocated brick last changed.
  const std::vector<std::uint64_t>& brickChangeStamps() const { return brick_stamps_; }

 private:
  struct Channel {
    std::string name;
    std::size_t bytes_per_slot;
    std::uint32_t fill_bits;
    std::unique_ptr<accel::DeviceBuffer> buffer;
  };
  bool brickInsideRegion(int bx, int by, int bz) const;
  void ensureCapacity(std::size_t bricks);
  std::unique_ptr<accel::DeviceBuffer> makeChannelBuffer(const Channel& c, std::size_t slots,
                                                         const accel::DeviceBuffer* old,
                                                         std::size_t old_slots);
  void uploadTables();

  accel::Backend& backend_;
  GridGeometry geometry_;
  BrickAllocation allocation_;
  accel::BrickedGridParams params_{};
  std::vector<int> table_;         // brick -> allocation index (| FVP_BRICK_INSIDE) or kNoBrick
  std::vector<int> brick_coords_;  // allocation index -> brick grid coordinates (x, y, z)
  std::size_t capacity_bricks_ = 0;
  std::vector<Channel> channels_;
  std::unique_ptr<accel::DeviceBuffer> table_buf_, coords_buf_;
  std::uint64_t layout_version_ = 0;
  std::uint64_t change_count_ = 0;
  std::vector<std::uint64_t> brick_stamps_;
};

}  // namespace fvp::host::map
