// Each `fvp` subcommand registers itself on the CLI11 app; the handlers only parse
// options and call the library.
#pragma once

#include <CLI/CLI.hpp>

#include <memory>
#include <string>
#include <vector>

// A subcommand's work, set as its callback. The parse-only build of the command-line fuzz
// harness (fuzz/cli_fuzzer.cpp, -DFVP_CLI_PARSE_ONLY) compiles the options and their checks
// without the work, so it links none of the libraries the work needs.
#ifdef FVP_CLI_PARSE_ONLY
#define FVP_ON_RUN(cmd, ...) ((void)(cmd))
#else
#define FVP_ON_RUN(cmd, ...) (cmd)->callback(__VA_ARGS__)
#endif

namespace fvp::apps {

void addBackendsCommand(CLI::App& app);
void addCaptureCommand(CLI::App& app);
void addTraverseCommand(CLI::App& app);
void addMapCommand(CLI::App& app);
void addRunCommand(CLI::App& app);
void addPlanCommand(CLI::App& app);
void addSizeCommand(CLI::App& app);
void addSeasonCommand(CLI::App& app);
void addSeasonsCommand(CLI::App& app);
void addExperimentCommands(CLI::App& app);

/// Keeps p alive until the running runFvp returns (no-op outside runFvp).
void keepForRun(std::shared_ptr<void> p);

/// What a subcommand's options are read into. CLI11 holds references to it, so it lives as
/// long as the command line, not only as long as the subcommand's work holds it: the
/// parse-only mode and build run no work.
template <typename T>
std::shared_ptr<T> optionStorage() {
  auto p = std::make_shared<T>();
  keepForRun(p);
  return p;
}

/// The names --planner and --engine take: the registries' (cli_vocabulary.cpp).
std::vector<std::string> plannerNames();
std::vector<std::string> mapEngineNames();

enum class CliMode {
  kRun,        ///< parse, check and do the work
  kParseOnly,  ///< parse and check the options only (the fuzz harness): no subcommand runs
};

/// The whole command line: `fvp` is runFvp(argc, argv, CliMode::kRun). Returns the exit code
/// (0, 1 for a bad file or value, 2 for a usage error); messages go to stderr.
int runFvp(int argc, const char* const* argv, CliMode mode);

}  // namespace fvp::apps
