#include "fvp/host/map/scan_integrator.h"

#include <stdexcept>

#include "fvp/accel/kernels.h"
#include "fvp/accel/sequence.h"

namespace fvp::host::map {

ScanIntegrator::ScanIntegrator(OccupancyLayer& layer) : layer_(layer) {
  // Marks: one byte lane per slot in 32-bit words, zero between scans (the update pass
  // clears what the mark pass set), so new slots start zeroed.
  marks_ = layer.bricks().addChannel("scan_marks", 1, 0u);
  const std::size_t bricks = layer.bricks().gridBricks();
  missing_ = layer.bricks().backend().createBufferFrom(std::vector<std::uint32_t>(bricks + 1, 0u));
  counter_ = layer.bricks().backend().createBuffer(sizeof(std::uint32_t));
}

std::size_t ScanIntegrator::integrate(accel::DeviceBuffer& points, std::uint32_t point_count,
                                      const Eigen::Vector3f& sensor_m,
                                      const OccupancyModel& model) {
  BrickLayer& bricks = layer_.bricks();
  accel::Backend& backend = bricks.backend();
  accel::ScanParams scan{};
  scan.map = bricks.params();
  scan.sensor_x_m = sensor_m.x();
  scan.sensor_y_m = sensor_m.y();
  scan.sensor_z_m = sensor_m.z();
  scan.point_count = point_count;
  scan.brick_count = static_cast<int>(bricks.gridBricks());
  const auto grid_bricks = static_cast<std::uint32_t>(bricks.gridBricks());
  for (int attempt = 0;; ++attempt) {
    scan.slot_count = static_cast<std::uint32_t>(bricks.capacitySlots());
    // The marks and, where bricks are allocated on touch, the flag of missing ones read
    // back in the same submission.
    std::uint32_t any_missing = 0;
    accel::Sequence mark(backend);
    mark.run(accel::kernels::scanMark(), scan,
             {&points, &bricks.tableBuffer(), &bricks.channel(marks_), missing_.get()});
    const bool on_touch = bricks.allocation() != BrickAllocation::kUpFront;
    if (on_touch)
      mark.download(*missing_, &any_missing, sizeof(any_missing),
                    grid_bricks * sizeof(std::uint32_t));
    mark.eval();
    if (!on_touch || !any_missing) break;
    if (attempt > 0)
      throw std::logic_error("ScanIntegrator: bricks still missing after allocation");
    // Allocate every brick the rays reached, in ascending order (the same on every
    // backend), then mark again: marks are idempotent, and grown channels keep theirs.
    std::vector<std::uint32_t> flags(grid_bricks + 1);
    backend.download(*missing_, flags.data(), flags.size() * sizeof(std::uint32_t));
    std::vector<int> ids;
    for (std::uint32_t b = 0; b < grid_bricks; ++b)
      if (flags[b]) ids.push_back(static_cast<int>(b));
    bricks.allocate(ids);
    std::fill(flags.begin(), flags.end(), 0u);
    backend.upload(*missing_, flags.data(), flags.size() * sizeof(std::uint32_t));
  }
  accel::UpdateParams update{};
  update.slot_count = static_cast<std::uint32_t>(bricks.capacitySlots());
  update.hit_logodds = model.hitLogOdds();
  update.miss_logodds = model.missLogOdds();
  update.clamp_min_logodds = model.clampMinLogOdds();
  update.clamp_max_logodds = model.clampMaxLogOdds();
  update.has_roi = layer_.hasRoi();
  // Reset, update and both read-backs in one submission.
  const std::uint32_t zero = 0;
  const std::vector<std::uint32_t> no_change(bricks.capacitySlots() / accel::kBrickVoxels, 0u);
  auto changed = backend.createBuffer(no_change.size() * sizeof(std::uint32_t));
  std::uint32_t updated = 0;
  std::vector<std::uint32_t> flags(bricks.allocatedBricks());
  accel::Sequence(backend)
      .upload(*counter_, &zero, sizeof(zero))
      .upload(*changed, no_change.data(), no_change.size() * sizeof(std::uint32_t))
      .run(accel::kernels::scanUpdate(), update,
           {&bricks.channel(marks_), &layer_.occupancy(), layer_.hasRoi() ? &layer_.roi() : nullptr,
            counter_.get(), changed.get()})
      .download(*counter_, &updated, sizeof(updated))
      .download(*changed, flags.data(), flags.size() * sizeof(std::uint32_t))
      .eval();
  std::vector<std::uint32_t> changed_bricks;
  for (std::uint32_t b = 0; b < flags.size(); ++b)
    if (flags[b]) changed_bricks.push_back(b);
  bricks.markChanged(changed_bricks);
  return updated;
}

}  // namespace fvp::host::map
