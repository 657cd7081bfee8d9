// Helpers shared by the fvp_bench families.
#pragma once

#include <benchmark/benchmark.h>
#include <omp.h>

#include <cstdint>
#include <memory>

#include "fvp/accel/backend.h"

namespace fvp::bench {

/// Voxel steps as items_per_second (the natural unit of traversal kernels) and the rays
/// (one per viewpoint in paper Eq. 2) as rays_per_second.
inline void setThroughput(benchmark::State& state, std::uint64_t steps_per_iteration,
                          std::uint64_t rays_per_iteration) {
  state.SetItemsProcessed(static_cast<int64_t>(steps_per_iteration) * state.iterations());
  state.counters["rays_per_second"] = benchmark::Counter(
      static_cast<double>(rays_per_iteration) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["steps_per_ray"] =
      static_cast<double>(steps_per_iteration) / static_cast<double>(rays_per_iteration);
}

/// The backend, or null after marking the benchmark skipped with the reason it is unavailable.
inline std::unique_ptr<accel::Backend> backendOrSkip(benchmark::State& state,
                                                     accel::BackendKind kind) {
  try {
    return accel::createBackend(kind);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return nullptr;
  }
}

/// Limits OpenMP to `threads` (0: leave as is) for one benchmark, restoring it after.
class OmpThreadsScope {
 public:
  explicit OmpThreadsScope(int threads) : saved_(omp_get_max_threads()) {
    if (threads > 0) omp_set_num_threads(threads);
  }
  ~OmpThreadsScope() { omp_set_num_threads(saved_); }
  OmpThreadsScope(const OmpThreadsScope&) = delete;
  OmpThreadsScope& operator=(const OmpThreadsScope&) = delete;

 private:
  int saved_;
};

}  // namespace fvp::bench
