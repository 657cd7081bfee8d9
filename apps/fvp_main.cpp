// fvp: command-line entry point. Options are parsed in cli.cpp; the work is in the libraries.
#include <csignal>

#include "commands.h"
#include "fvp/host/core/interrupt.h"

int main(int argc, char** argv) {
  // SIGINT/SIGTERM stop the run cleanly (docs/reliability.md, "Signals"); a file size limit
  // (ulimit -f) fails the write with EFBIG instead of killing fvp with SIGXFSZ.
  fvp::host::installInterruptHandlers();
  std::signal(SIGXFSZ, SIG_IGN);
  return fvp::apps::runFvp(argc, argv, fvp::apps::CliMode::kRun);
}
