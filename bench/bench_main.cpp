// fvp_bench: every benchmark family of the project in one program, so that ours and the
// peers (OctoMap, Open3D) run on the same data in the same run.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <iostream>

#include "fvp/accel/backend.h"

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  for (const auto& info : fvp::accel::probeBackends()) {
    benchmark::AddCustomContext("backend_" + std::string(fvp::accel::toString(info.kind)),
                                info.available ? info.device : "unavailable: " + info.reason);
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  std::cerr << "peak resident memory of the whole run: " << usage.ru_maxrss / 1024 << " MB\n";
  return 0;
}
