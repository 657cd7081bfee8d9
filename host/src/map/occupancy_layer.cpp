#include "fvp/host/map/occupancy_layer.h"

#include <limits>
#include <stdexcept>

#include "fvp/accel/sequence.h"

namespace fvp::host::map {
namespace {

constexpr float kUnknown = std::numeric_limits<float>::quiet_NaN();
constexpr std::uint32_t kQuietNanBits = 0x7fc00000u;

}  // namespace

OccupancyLayer::OccupancyLayer(accel::Backend& backend, const GridGeometry& geometry, bool with_roi,
                               std::optional<fvp_region> region, BrickAllocation allocation)
    : bricks_(backend, geometry, region, allocation), with_roi_(with_roi) {
  occupancy_ = bricks_.addChannel("occupancy", sizeof(float), kQuietNanBits);
  if (with_roi) roi_ = bricks_.addChannel("roi", sizeof(float), kQuietNanBits);
}

accel::DeviceBuffer& OccupancyLayer::roi() {
  if (!roi_) throw std::logic_error("OccupancyLayer::roi: this map has no ROI channel");
  return bricks_.channel(*roi_);
}

void OccupancyLayer::refreshMirror() const {
  // Every voxel read calls this: the common case, a current mirror, takes no lock. (The
  // layer does not change during const reads, so the two counts cannot move under us.)
  const auto current = [&] {
    return mirror_change_count_.load(std::memory_order_acquire) == bricks_.changeCount() &&
           mirror_slots_.load(std::memory_order_acquire) == bricks_.slotCount();
  };
  if (current()) return;
  // Const reads may come from several threads; the first one refreshes the mirror.
  std::lock_guard<std::mutex> lock(mirror_mutex_);
  if (current()) return;
  const std::size_t slots = bricks_.slotCount();
  const std::uint64_t since = mirror_change_count_.load(std::memory_order_relaxed);
  // New bricks hold the channels' fill (unknown) until an operation marks them changed.
  mirror_occupancy_.resize(slots, kUnknown);
  if (with_roi_) mirror_roi_.resize(slots, kUnknown);
  const auto& stamps = bricks_.brickChangeStamps();
  auto& backend = bricks_.backend();
  // Download runs of consecutive changed bricks, one transfer per run, all in one submission.
  accel::Sequence seq(backend);
  std::size_t b = 0;
  while (b < stamps.size()) {
    if (stamps[b] <= since) {
      ++b;
      continue;
    }
    std::size_t end = b + 1;
    while (end < stamps.size() && stamps[end] > since) ++end;
    const std::size_t first = b * accel::kBrickVoxels, count = (end - b) * accel::kBrickVoxels;
    seq.download(bricks_.channel(occupancy_), mirror_occupancy_.data() + first,
                 count * sizeof(float), first * sizeof(float));
    if (with_roi_)
      seq.download(bricks_.channel(*roi_), mirror_roi_.data() + first, count * sizeof(float),
                   first * sizeof(float));
    b = end;
  }
  seq.eval();
  mirror_slots_.store(slots, std::memory_order_release);
  mirror_change_count_.store(bricks_.changeCount(), std::memory_order_release);
}

float OccupancyLayer::occupancyAt(const std::array<int, 3>& index) const {
  const std::int64_t slot = bricks_.slotOf(index);
  if (slot < 0) return kUnknown;
  refreshMirror();
  return mirror_occupancy_[static_cast<std::size_t>(slot)];
}

float OccupancyLayer::roiAt(const std::array<int, 3>& index) const {
  const std::int64_t slot = bricks_.slotOf(index);
  if (slot < 0 || !with_roi_) return kUnknown;
  refreshMirror();
  return mirror_roi_[static_cast<std::size_t>(slot)];
}

void OccupancyLayer::assignDense(const std::vector<float>& occupancy_values,
                                 const std::vector<float>& roi_values) {
  const GridGeometry& g = geometry();
  const auto voxels = static_cast<std::size_t>(g.voxelCount());
  if (occupancy_values.size() != voxels || (with_roi_ && roi_values.size() != voxels))
    throw std::invalid_argument(
        "OccupancyLayer::assignDense: arrays must hold one value per grid voxel");
  bricks_.allocateAll();
  const std::size_t slots = bricks_.slotCount();
  std::vector<float> occ(slots, kUnknown), roi_slots(with_roi_ ? slots : 0, kUnknown);
  std::size_t dense = 0;
  for (int z = 0; z < g.dims[2]; ++z)
    for (int y = 0; y < g.dims[1]; ++y)
      for (int x = 0; x < g.dims[0]; ++x, ++dense) {
        const auto slot = static_cast<std::size_t>(bricks_.slotOf({x, y, z}));
        occ[slot] = occupancy_values[dense];
        if (with_roi_) roi_slots[slot] = roi_values[dense];
      }
  auto& backend = bricks_.backend();
  backend.upload(occupancy(), occ.data(), slots * sizeof(float));
  if (with_roi_) backend.upload(roi(), roi_slots.data(), slots * sizeof(float));
  bricks_.markAllChanged();
}

}  // namespace fvp::host::map
