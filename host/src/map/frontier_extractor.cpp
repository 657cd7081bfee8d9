#include "fvp/host/map/frontier_extractor.h"

#include <algorithm>
#include <cstring>
#include <iterator>
#include <stdexcept>
#include <tuple>

#include "fvp/accel/kernels.h"
#include "fvp/accel/sequence.h"

namespace fvp::host::map {
namespace {

bool byGridIndex(const FrontierVoxel& a, const FrontierVoxel& b) {
  return std::tie(a.index[2], a.index[1], a.index[0]) <
         std::tie(b.index[2], b.index[1], b.index[0]);
}

bool sameBits(float a, float b) {
  return std::memcmp(&a, &b, sizeof(float)) == 0;
}

}  // namespace

FrontierExtractor::FrontierExtractor(OccupancyLayer& layer) : layer_(layer) {
  if (!layer.hasRoi()) throw std::logic_error("FrontierExtractor needs a map with ROI");
  counter_ = layer.bricks().backend().createBuffer(sizeof(std::uint32_t));
}

std::vector<std::uint32_t> FrontierExtractor::bricksToReclassify(
    std::vector<char>& reclassified) const {
  const BrickLayer& bricks = layer_.bricks();
  const accel::BrickedGridParams& grid = bricks.params();
  const std::vector<int>& coords = bricks.brickCoords();
  const std::vector<std::uint64_t>& stamps = bricks.brickChangeStamps();
  reclassified.assign(bricks.gridBricks(), 0);
  std::vector<std::uint32_t> out;
  for (std::size_t b = 0; b < stamps.size(); ++b) {
    if (stamps[b] <= last_change_count_) continue;
    const int* c = &coords[3 * b];
    for (int z = std::max(0, c[2] - 1); z <= std::min(grid.bricks_z - 1, c[2] + 1); ++z)
      for (int y = std::max(0, c[1] - 1); y <= std::min(grid.bricks_y - 1, c[1] + 1); ++y)
        for (int x = std::max(0, c[0] - 1); x <= std::min(grid.bricks_x - 1, c[0] + 1); ++x) {
          const int id = bricks.brickIndex(x, y, z);
          if (reclassified[id]) continue;
          reclassified[id] = 1;
          // An unallocated brick is unknown space: it holds no frontier.
          const int entry = bricks.table()[id];
          if (entry != accel::kNoBrick) out.push_back(entry & FVP_BRICK_INDEX_MASK);
        }
  }
  return out;
}

std::vector<FrontierVoxel> FrontierExtractor::classify(accel::DeviceBuffer& coords,
                                                       std::size_t brick_count,
                                                       float occupied_logodds) {
  BrickLayer& bricks = layer_.bricks();
  accel::Backend& backend = bricks.backend();
  accel::FrontierParams params{};
  params.map = bricks.params();
  params.occupied_logodds = occupied_logodds;
  // The items are the listed bricks' voxels; each reads the channels of any allocated brick
  // through the table (the bindings' sizes are minimums, the channels hold every slot).
  params.slot_count = static_cast<std::uint32_t>(brick_count * accel::kBrickVoxels);
  std::vector<accel::Frontier> raw;
  for (;;) {
    params.capacity = capacity_;
    auto out = backend.createBuffer(std::size_t{capacity_} * sizeof(accel::Frontier));
    const std::uint32_t zero = 0;
    std::uint32_t found = 0;
    accel::Sequence(backend)
        .upload(*counter_, &zero, sizeof(zero))
        .run(accel::kernels::frontier(), params,
             {&coords, &bricks.tableBuffer(), &layer_.occupancy(), &layer_.roi(), out.get(),
              counter_.get()})
        .download(*counter_, &found, sizeof(found))
        .eval();
    if (found <= capacity_) {
      raw.resize(found);
      if (found) backend.download(*out, raw.data(), found * sizeof(accel::Frontier));
      break;
    }
    capacity_ = found;  // too small: run again with room for all
  }
  std::vector<FrontierVoxel> frontiers;
  frontiers.reserve(raw.size());
  for (const auto& f : raw) {
    FrontierVoxel v;
    v.index = {f.x, f.y, f.z};
    v.center_m = layer_.geometry().voxelCenter_m(v.index);
    v.roi_frontier = (f.flags & FVP_FRONTIER_ROI) != 0;
    v.exploration_frontier = (f.flags & FVP_FRONTIER_EXPLORE) != 0;
    const Eigen::Vector3d n(f.normal_x, f.normal_y, f.normal_z);
    if (n.squaredNorm() > 0) v.normal = n.normalized();
    frontiers.push_back(v);
  }
  // Kernels append in any order: sort by grid index for a deterministic result.
  std::sort(frontiers.begin(), frontiers.end(), byGridIndex);
  return frontiers;
}

std::vector<FrontierVoxel> FrontierExtractor::extract(float occupied_logodds) {
  BrickLayer& bricks = layer_.bricks();
  stats_ = {};
  stats_.allocated_bricks = bricks.allocatedBricks();
  std::vector<char> reclassified;
  std::vector<std::uint32_t> changed;
  // A new threshold changes every voxel's class; so many changes are cheaper whole.
  bool incremental = have_last_ && sameBits(occupied_logodds, last_occupied_logodds_);
  if (incremental) {
    changed = bricksToReclassify(reclassified);
    incremental = changed.size() < stats_.allocated_bricks;
  }
  if (!incremental) {
    last_ = classify(bricks.coordsBuffer(), stats_.allocated_bricks, occupied_logodds);
    stats_.classified_bricks = stats_.allocated_bricks;
  } else {
    stats_.full = false;
    stats_.classified_bricks = changed.size();
    std::vector<FrontierVoxel> fresh;
    if (!changed.empty()) {
      std::vector<int> coords;
      coords.reserve(3 * changed.size());
      for (std::uint32_t b : changed) {
        const int* c = bricks.brickCoords().data() + 3 * std::size_t{b};
        coords.insert(coords.end(), c, c + 3);
      }
      accel::Backend& backend = bricks.backend();
      if (changed.size() > changed_coords_capacity_) {
        changed_coords_capacity_ = std::max(changed.size(), 2 * changed_coords_capacity_);
        changed_coords_ = backend.createBuffer(changed_coords_capacity_ * 3 * sizeof(int));
      }
      backend.upload(*changed_coords_, coords.data(), coords.size() * sizeof(int));
      fresh = classify(*changed_coords_, changed.size(), occupied_logodds);
    }
    // The kept frontiers lie in bricks not classified again; both lists are sorted.
    const auto brick_of = [&](const FrontierVoxel& v) {
      return bricks.brickIndex(v.index[0] >> 3, v.index[1] >> 3, v.index[2] >> 3);
    };
    std::vector<FrontierVoxel> kept;
    kept.reserve(last_.size());
    std::copy_if(last_.begin(), last_.end(), std::back_inserter(kept),
                 [&](const FrontierVoxel& v) { return !reclassified[brick_of(v)]; });
    last_.clear();
    std::merge(kept.begin(), kept.end(), fresh.begin(), fresh.end(), std::back_inserter(last_),
               byGridIndex);
  }
  have_last_ = true;
  last_change_count_ = bricks.changeCount();
  last_occupied_logodds_ = occupied_logodds;
  return last_;
}

}  // namespace fvp::host::map
