#include <iomanip>
#include <iostream>

#include "commands.h"
#include "fvp/accel/backend.h"

namespace fvp::apps {

void addBackendsCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("backends", "List the compute backends and their devices");
  FVP_ON_RUN(cmd, [] {
    for (const auto& info : accel::probeBackends()) {
      std::cout << std::left << std::setw(8) << accel::toString(info.kind)
                << (info.available ? "available    " : "unavailable  ")
                << (info.available ? info.device + (info.is_gpu ? " [gpu]" : " [cpu]")
                                   : info.reason)
                << "\n";
    }
  });
}

}  // namespace fvp::apps
