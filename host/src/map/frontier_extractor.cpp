#include "fvp/host/map/frontier_extractor.h"

#include <algorithm>
#include <stdexcept>
#include <tuple>

#include "fvp/accel/kernels.h"

namespace fvp::host::map {

FrontierExtractor::FrontierExtractor(OccupancyLayer& layer) : layer_(layer) {
  if (!layer.hasRoi()) throw std::logic_error("FrontierExtractor needs a map with ROI");
  counter_ = layer.bricks().backend().createBuffer(sizeof(std::uint32_t));
}

std::vector<FrontierVoxel> FrontierExtractor::extract(float occupied_logodds) {
  BrickLayer& bricks = layer_.bricks();
  accel::Backend& backend = bricks.backend();
  accel::FrontierParams params{};
  params.map = bricks.params();
  params.occupied_logodds = occupied_logodds;
  params.slot_count = static_cast<std::uint32_t>(bricks.slotCount());
  std::vector<accel::Frontier> raw;
  for (;;) {
    params.capacity = capacity_;
    auto out = backend.createBuffer(std::size_t{capacity_} * sizeof(accel::Frontier));
    const std::uint32_t zero = 0;
    backend.upload(*counter_, &zero, sizeof(zero));
    backend.run(accel::kernels::frontier(), params,
                {&bricks.coordsBuffer(), &bricks.tableBuffer(), &layer_.occupancy(), &layer_.roi(),
                 out.get(), counter_.get()});
    std::uint32_t found = 0;
    backend.download(*counter_, &found, sizeof(found));
    if (found <= capacity_) {
      raw.resize(found);
      if (found) backend.download(*out, raw.data(), found * sizeof(accel::Frontier));
      break;
    }
    capacity_ = found;  // too small: run again with room for all
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
    v.center_m = layer_.geometry().voxelCenter_m(v.index);
    v.roi_frontier = (f.flags & FVP_FRONTIER_ROI) != 0;
    v.exploration_frontier = (f.flags & FVP_FRONTIER_EXPLORE) != 0;
    const Eigen::Vector3d n(f.normal_x, f.normal_y, f.normal_z);
    if (n.squaredNorm() > 0) v.normal = n.normalized();
    frontiers.push_back(v);
  }
  return frontiers;
}

}  // namespace fvp::host::map
