// The command line: every subcommand's options on one CLI11 app, and the exit codes.
#include <exception>
#include <iostream>
#include <new>
#include <string>

#include "commands.h"
#include "fvp/host/core/interrupt.h"

namespace fvp::apps {
namespace {

// The running runFvp's option storage (optionStorage); null outside runFvp.
thread_local std::vector<std::shared_ptr<void>>* kept = nullptr;

}  // namespace

void keepForRun(std::shared_ptr<void> p) {
  if (kept) kept->push_back(std::move(p));
}

int runFvp(int argc, const char* const* argv, CliMode mode) {
  // Declared before the app: the app (which refers to the storage) goes first.
  std::vector<std::shared_ptr<void>> storage;
  struct Keeping {
    explicit Keeping(std::vector<std::shared_ptr<void>>* s) { kept = s; }
    ~Keeping() { kept = nullptr; }
  } keeping(&storage);
  CLI::App app{"fvp: apple-fruitlet sizing with next-best-view planning"};
  app.require_subcommand(1);
  addBackendsCommand(app);
  addCaptureCommand(app);
  addTraverseCommand(app);
  addMapCommand(app);
  addRunCommand(app);
  addPlanCommand(app);
  addSizeCommand(app);
  addSeasonCommand(app);
  addSeasonsCommand(app);
  addExperimentCommands(app);
  if (mode == CliMode::kParseOnly)
    for (CLI::App* sub : app.get_subcommands({})) sub->callback([] {});
  // CLI11 reports a mistyped subcommand as "A subcommand is required"; name it instead.
  if (argc > 1 && argv[1][0] != '-') {
    std::string known;
    bool found = false;
    for (const CLI::App* sub : app.get_subcommands({})) {
      found |= sub->get_name() == argv[1];
      known += (known.empty() ? "" : ", ") + sub->get_name();
    }
    if (!found) {
      std::cerr << "fvp: error: unknown subcommand '" << argv[1] << "' (known: " << known
                << "; see fvp --help)\n";
      return 2;
    }
  }
  const auto command = [&app] {
    const auto used = app.get_subcommands();
    return used.empty() ? std::string("fvp") : "fvp " + used.front()->get_name();
  };
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Usage errors exit 2 (CLI11's own codes are 100+); --help exits 0.
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const std::bad_alloc&) {
    // A setting's memory is estimated before the large allocations; one that got past them
    // still ends with a message naming the command, not a bare std::bad_alloc.
    std::cerr << "fvp: error: " << command()
              << ": out of memory (a setting, a config or an input asked for more memory than "
                 "there is; see docs/reliability.md, \"Memory bounds\")\n";
    return 1;
  } catch (const std::exception& e) {
    if (const int sig = host::interruptSignal()) {
      std::cerr << "fvp: " << command() << ": " << e.what()
                << "; files that were complete are kept\n";
      return 128 + sig;
    }
    std::cerr << "fvp: error: " << e.what() << "\n";
    return 1;
  }
  if (const int sig = host::interruptSignal()) {
    std::cerr << "fvp: " << command() << ": interrupted by signal " << sig << " at its end\n";
    return 128 + sig;
  }
  return 0;
}

}  // namespace fvp::apps
