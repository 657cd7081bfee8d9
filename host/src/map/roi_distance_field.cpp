#include "fvp/host/map/roi_distance_field.h"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#include "fvp/accel/kernels.h"
#include "fvp/accel/sequence.h"

namespace fvp::host::map {

RoiDistanceField::RoiDistanceField(OccupancyLayer& layer) : layer_(layer) {
  if (!layer.hasRoi()) throw std::logic_error("RoiDistanceField needs a map with ROI");
}

accel::DeviceBuffer& RoiDistanceField::distanceVox() {
  if (!distance_) throw std::logic_error("RoiDistanceField: call compute() first");
  return layer_.bricks().channel(*distance_);
}

bool RoiDistanceField::current() const {
  return computed_ && computed_change_ == layer_.bricks().changeCount() &&
         computed_layout_ == layer_.bricks().layoutVersion();
}

std::vector<char> RoiDistanceField::roiHalo(int radius_vox) const {
  // A distance below the cap comes from an ROI voxel within radius_vox, through pass values
  // at voxels of the box spanned by the two, all within radius_vox of that ROI voxel. So
  // only bricks closer than radius_vox to an ROI brick (nearest voxels, Euclidean) need the
  // passes; the others read "far", which can only yield the cap.
  const BrickLayer& bricks = layer_.bricks();
  const accel::BrickedGridParams& m = bricks.params();
  const int halo = (radius_vox + accel::kBrickEdge - 1) / accel::kBrickEdge;
  const auto gap = [](int bricks_apart) {  // voxels between the nearest voxels of two bricks
    return std::max(0, accel::kBrickEdge * std::abs(bricks_apart) - (accel::kBrickEdge - 1));
  };
  std::vector<char> near(bricks.gridBricks(), 0);
  for (std::size_t b = 0; b < bricks.allocatedBricks(); ++b) {
    bool has_roi = false;
    layer_.forEachVoxelOfBrick(
        b, [&](const std::array<int, 3>&, float, float roi) { has_roi = has_roi || roi > 0.0f; });
    if (!has_roi) continue;
    const int* c = &bricks.brickCoords()[3 * b];
    for (int z = std::max(0, c[2] - halo); z <= std::min(m.bricks_z - 1, c[2] + halo); ++z)
      for (int y = std::max(0, c[1] - halo); y <= std::min(m.bricks_y - 1, c[1] + halo); ++y)
        for (int x = std::max(0, c[0] - halo); x <= std::min(m.bricks_x - 1, c[0] + halo); ++x) {
          const int gx = gap(x - c[0]), gy = gap(y - c[1]), gz = gap(z - c[2]);
          if (gx * gx + gy * gy + gz * gz < radius_vox * radius_vox)
            near[bricks.brickIndex(x, y, z)] = 1;
        }
  }
  return near;
}

void RoiDistanceField::compute(int radius_vox) {
  BrickLayer& bricks = layer_.bricks();
  // The previous distances, to tell readers which bricks this computation changed.
  std::vector<float> previous;
  const int previous_radius_vox = computed_ ? radius_vox_ : -1;
  if (computed_) {
    std::lock_guard<std::mutex> lock(mirror_mutex_);
    downloadMirrorLocked();
    previous = std::move(mirror_);
    mirror_.clear();
    mirror_ready_.store(false, std::memory_order_release);
  }
  // The channel costs 4 bytes per slot: added when first needed.
  if (!distance_) distance_ = bricks.addChannel("roi_distance_vox", sizeof(float), 0u);
  std::vector<char> near = roiHalo(radius_vox);
  if (bricks.allocation() == BrickAllocation::kOnTouch) {
    // The passes carry distances through every near voxel (the x pass result at
    // (qx, py, pz) is what carries p's distance to q): each needs a slot.
    std::vector<int> ids;
    for (std::size_t id = 0; id < near.size(); ++id)
      if (near[id] && bricks.table()[id] == accel::kNoBrick) ids.push_back(static_cast<int>(id));
    bricks.allocate(ids);
  }
  // The passes run over the near bricks only: elsewhere every pass value is "far" and the
  // distance the cap, filled here. Most of a Cluster Region is far from every fruitlet.
  std::vector<std::uint32_t> work;
  for (std::size_t id = 0; id < near.size(); ++id)
    if (near[id])
      work.push_back(static_cast<std::uint32_t>(bricks.table()[id] & FVP_BRICK_INDEX_MASK));
  accel::Backend& backend = bricks.backend();
  const std::size_t slots = bricks.slotCount();
  // The fill and the three passes in one submission.
  accel::Sequence seq(backend);
  const std::vector<float> cap(slots, float(radius_vox));
  seq.upload(distanceVox(), cap.data(), slots * sizeof(float));
  // Read by eval(): alive until then.
  std::unique_ptr<accel::DeviceBuffer> sq_a, sq_b, work_bricks;
  std::vector<std::uint32_t> far;
  if (!work.empty()) {
    accel::EdtParams edt{};
    edt.map = bricks.params();
    edt.radius_vox = radius_vox;
    edt.slot_count = static_cast<std::uint32_t>(slots);
    edt.work_brick_count = static_cast<std::uint32_t>(work.size());
    far.assign(slots, FVP_EDT_FAR);
    sq_a = backend.createBuffer(slots * sizeof(std::uint32_t));
    sq_b = backend.createBuffer(slots * sizeof(std::uint32_t));
    work_bricks = backend.createBuffer(work.size() * sizeof(std::uint32_t));
    seq.upload(*sq_a, far.data(), slots * sizeof(std::uint32_t))
        .upload(*sq_b, far.data(), slots * sizeof(std::uint32_t))
        .upload(*work_bricks, work.data(), work.size() * sizeof(std::uint32_t));
    // x pass: roi -> sq_a; y pass: sq_a -> sq_b; z pass: sq_b -> distance.
    const auto kernel = accel::kernels::roiDistance();
    auto* coords = &bricks.coordsBuffer();
    auto* table = &bricks.tableBuffer();
    edt.axis = 0;
    seq.run(kernel, edt,
            {coords, table, &layer_.roi(), nullptr, sq_a.get(), nullptr, work_bricks.get()});
    edt.axis = 1;
    seq.run(kernel, edt,
            {coords, table, nullptr, sq_a.get(), sq_b.get(), nullptr, work_bricks.get()});
    edt.axis = 2;
    seq.run(kernel, edt,
            {coords, table, nullptr, sq_b.get(), nullptr, &distanceVox(), work_bricks.get()});
  }
  seq.eval();
  radius_vox_ = radius_vox;
  computed_slots_ = slots;
  computed_ = true;
  computed_change_ = bricks.changeCount();
  computed_layout_ = bricks.layoutVersion();
  std::lock_guard<std::mutex> lock(mirror_mutex_);
  mirror_.clear();
  downloadMirrorLocked();
  findChangedBricks(previous, previous_radius_vox);
}

void RoiDistanceField::downloadMirrorLocked() const {
  if (mirror_.empty()) {
    mirror_.resize(computed_slots_);
    const BrickLayer& bricks = layer_.bricks();
    bricks.backend().download(bricks.channel(*distance_), mirror_.data(),
                              mirror_.size() * sizeof(float));
  }
  mirror_ready_.store(true, std::memory_order_release);
}

void RoiDistanceField::findChangedBricks(const std::vector<float>& previous,
                                         int previous_radius_vox) {
  changed_bricks_.clear();
  const std::size_t bricks = computed_slots_ / accel::kBrickVoxels;
  for (std::size_t b = 0; b < bricks; ++b) {
    bool changed = previous_radius_vox != radius_vox_;
    // Slots allocated since the previous computation read the cap before it.
    for (std::size_t slot = b * accel::kBrickVoxels;
         !changed && slot < (b + 1) * accel::kBrickVoxels; ++slot)
      changed =
          mirror_[slot] != (slot < previous.size() ? previous[slot] : float(previous_radius_vox));
    if (changed) changed_bricks_.push_back(static_cast<std::uint32_t>(b));
  }
}

float RoiDistanceField::distanceVoxAt(const std::array<int, 3>& index) const {
  if (!computed_) throw std::logic_error("RoiDistanceField: call compute() first");
  const BrickLayer& bricks = layer_.bricks();
  const std::int64_t slot = bricks.slotOf(index);
  // Bricks allocated after compute() were not in it: the cap, as for unallocated ones.
  if (slot < 0 || static_cast<std::size_t>(slot) >= computed_slots_)
    return static_cast<float>(radius_vox_);
  // The snapshot reads every voxel: once the mirror is down, no lock.
  if (!mirror_ready_.load(std::memory_order_acquire)) {
    std::lock_guard<std::mutex> lock(mirror_mutex_);
    downloadMirrorLocked();
  }
  return mirror_[static_cast<std::size_t>(slot)];
}

std::vector<float> RoiDistanceField::dense() const {
  const GridGeometry& g = layer_.geometry();
  std::vector<float> out(static_cast<std::size_t>(g.voxelCount()));
  std::size_t i = 0;
  for (int z = 0; z < g.dims[2]; ++z)
    for (int y = 0; y < g.dims[1]; ++y)
      for (int x = 0; x < g.dims[0]; ++x) out[i++] = distanceVoxAt({x, y, z});
  return out;
}

}  // namespace fvp::host::map
