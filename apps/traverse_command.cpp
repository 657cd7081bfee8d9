#include <chrono>
#include <iostream>
#include <string>

#include "cli_checks.h"
#include "commands.h"
#include "fvp/accel/ray_workload.h"
#include "fvp/host/core/memory_budget.h"

namespace fvp::apps {

void addTraverseCommand(CLI::App& app) {
  struct Options {
    accel::BackendChoice backend = accel::BackendChoice::kAuto;
    int side_voxels = 160;
    float voxel_size_m = 0.001f;
    std::size_t rays = 100000;
    float outside_fraction = 0.5f;
    std::uint64_t seed = 1;
    bool check = true;
  };
  auto opt = optionStorage<Options>();
  auto* cmd =
      app.add_subcommand("traverse",
                         "Run the batched voxel ray traversal kernel on a synthetic canopy grid, "
                         "check it against the cpu reference and report voxel steps per second");
  addBackendOption(cmd, opt->backend, "compute backend");
  cmd->add_option("--side-voxels", opt->side_voxels, "grid side in voxels")
      ->check(decimalUnsigned())
      ->check(CLI::Range(8, 1024))
      ->capture_default_str();
  cmd->add_option("--voxel-size-m", opt->voxel_size_m, "voxel edge in metres")
      ->check(finiteNumber())
      ->check(CLI::Range(1e-4, 1.0))
      ->capture_default_str();
  cmd->add_option("--rays", opt->rays, "number of rays")
      ->check(decimalUnsigned())
      ->check(CLI::Range(1, 50000000))
      ->capture_default_str();
  cmd->add_option("--outside-fraction", opt->outside_fraction,
                  "fraction of rays starting outside the grid")
      ->check(finiteNumber())
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--seed", opt->seed, "workload seed")
      ->check(decimalUnsigned())
      ->capture_default_str();
  cmd->add_flag("!--no-check", opt->check, "skip the comparison with the cpu reference");
  FVP_ON_RUN(cmd, [opt] {
    using Clock = std::chrono::steady_clock;
    // The grid (two floats a voxel) on the host and the device, and the rays with their
    // results (twice with the check): 1024^3 voxels asked for 17 GiB.
    const std::uint64_t side = static_cast<std::uint64_t>(opt->side_voxels);
    host::checkMemoryFor(
        side * side * side * 2 * sizeof(float) * 2 + std::uint64_t(opt->rays) * 3 * 64,
        "traverse --side-voxels " + std::to_string(opt->side_voxels) + " --rays " +
            std::to_string(opt->rays));
    auto backend = accel::createBackend(opt->backend);
    const accel::DenseGrid grid =
        accel::makeCanopyGrid(opt->side_voxels, opt->voxel_size_m, opt->seed);
    const auto rays =
        accel::makeRandomRays(grid.params, {opt->rays, opt->outside_fraction}, opt->seed + 1);
    accel::traverseOnBackend(*backend, grid, rays);  // warm-up: first-use compilation, caches
    const auto t0 = Clock::now();
    const auto results = accel::traverseOnBackend(*backend, grid, rays);
    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    std::size_t by_status[4] = {};
    for (const auto& r : results) by_status[r.status < 4 ? r.status : 3]++;
    const auto steps = accel::totalSteps(results);
    std::cout << "backend        " << accel::toString(backend->kind()) << " ("
              << backend->deviceName() << ")\n"
              << "grid           " << opt->side_voxels << "^3 voxels of " << opt->voxel_size_m * 1e3
              << " mm\n"
              << "rays           " << rays.size() << " (reached end " << by_status[0]
              << ", hit occupied " << by_status[1] << ", left grid " << by_status[2] << ", invalid "
              << by_status[3] << ")\n"
              << "voxel steps    " << steps << "\n"
              << "time           " << seconds * 1e3 << " ms (upload + dispatch + download)\n"
              << "throughput     " << steps / seconds / 1e6 << " M voxel steps/s\n";
    if (opt->check && backend->kind() != accel::BackendKind::kCpu) {
      auto cpu = accel::createBackend(accel::BackendKind::kCpu);
      const auto reference = accel::traverseOnBackend(*cpu, grid, rays);
      std::size_t mismatches = 0;
      for (std::size_t i = 0; i < results.size(); ++i) {
        const auto& a = results[i];
        const auto& b = reference[i];
        if (a.steps != b.steps || a.stop_voxel != b.stop_voxel || a.status != b.status ||
            a.field_sum != b.field_sum)
          ++mismatches;
      }
      std::cout << "check vs cpu   " << (mismatches == 0 ? "identical" : "MISMATCH") << " ("
                << mismatches << " of " << results.size() << " rays differ)\n";
      if (mismatches) throw std::runtime_error("backend results differ from the cpu reference");
    }
  });
}

}  // namespace fvp::apps
