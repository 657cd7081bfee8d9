// Uses an installed fvp the way another project would: the compute backends with their
// embedded kernels, and one simulated view through perception into the maps. Exits non-zero
// on a wrong answer.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "fvp/accel/backend.h"
#include "fvp/accel/ray_workload.h"
#include "fvp/robot/sim/camera_views.h"
#include "fvp/robot/sim/simulated_mapping.h"
#include "fvp/robot/sim/world.h"
#include "fvp/robot/sim/world_config.h"

namespace {

int failures = 0;

void check(bool ok, const char* what) {
  std::printf("%-58s %s\n", what, ok ? "ok" : "WRONG");
  if (!ok) ++failures;
}

// An 8^3 grid of 1 cm free voxels with one occupied voxel at (5, 3, 3); a ray along +x
// through row (y, z) = (3, 3) visits voxels 0..5 and stops at the occupied one.
bool traversalIsRight(fvp::accel::Backend& backend) {
  fvp::accel::DenseGrid grid;
  grid.params = fvp::accel::makeGridParams({8, 8, 8}, {0.0f, 0.0f, 0.0f}, 0.01f);
  grid.occupancy.assign(8 * 8 * 8, fvp::accel::kMissLogOdds);
  grid.field.assign(8 * 8 * 8, 1.0f);
  const int occupied = 5 + 8 * (3 + 8 * 3);
  grid.occupancy[occupied] = fvp::accel::kHitLogOdds;
  fvp::accel::Ray ray{};
  ray.origin_m[0] = 0.005f, ray.origin_m[1] = 0.035f, ray.origin_m[2] = 0.035f;
  ray.end_m[0] = 0.075f, ray.end_m[1] = 0.035f, ray.end_m[2] = 0.035f;
  const std::vector<fvp::accel::RayResult> results =
      fvp::accel::traverseOnBackend(backend, grid, {ray});
  return results.size() == 1 && results[0].steps == 6 && results[0].stop_voxel == occupied &&
         results[0].status == FVP_RAY_HIT_OCCUPIED && results[0].field_sum == 6.0f;
}

}  // namespace

int main() {
  try {
    // Every backend this machine can run: the OpenCL and SPIR-V kernels are compiled into
    // the library, so nothing is read from fvp's source tree.
    for (const fvp::accel::BackendInfo& info : fvp::accel::probeBackends()) {
      const std::string name(fvp::accel::toString(info.kind));
      if (!info.available) {
        std::printf("%s: not available here (%s)\n", name.c_str(), info.reason.c_str());
        continue;
      }
      auto backend = fvp::accel::createBackend(info.kind);
      std::printf("%s: %s\n", name.c_str(), backend->deviceName().c_str());
      check(traversalIsRight(*backend), "  ray traversal stops at the occupied voxel");
    }

    // World 2's start view: its AprilTag places the Cluster Region, the grid engine on the
    // cpu backend maps the view.
    auto cpu = fvp::accel::createBackend("cpu");
    const auto world = fvp::robot::sim::World::generate(fvp::robot::sim::WorldConfig{}, 2);
    const auto poses = fvp::robot::sim::orbitViews(world, 1, 0.0);
    const auto mapped = fvp::robot::sim::mapSimulatedViews(
        world, poses, fvp::robot::sim::SimulatedMappingOptions{}, cpu.get());
    check(mapped.views.size() == 1 && mapped.views[0].tag_detected,
          "simulated start view: AprilTag detected");
    check(mapped.region.has_value() && mapped.map != nullptr, "Cluster Region placed, map made");
    if (mapped.map) {
      const auto fine = mapped.map->occupiedVoxels(fvp::host::map::MapLevel::kFine);
      const auto coarse = mapped.map->occupiedVoxels(fvp::host::map::MapLevel::kCoarse);
      std::printf("occupied voxels: %zu fine, %zu coarse; %zu ROI points\n", fine.size(),
                  coarse.size(), mapped.views[0].roi_points);
      check(!fine.empty() && !coarse.empty() && mapped.views[0].roi_points > 0,
            "the view's fruitlets are in the fine and coarse maps");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fvp_consumer: %s\n", e.what());
    return 1;
  }
  if (failures > 0) {
    std::fprintf(stderr, "fvp_consumer: %d wrong\n", failures);
    return 1;
  }
  std::printf("fvp_consumer: all checks passed\n");
  return 0;
}
