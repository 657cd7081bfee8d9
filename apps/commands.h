// Each `fvp` subcommand registers itself on the CLI11 app; the handlers only parse
// options and call the library.
#pragma once

#include <CLI/CLI.hpp>

namespace fvp::apps {

void addBackendsCommand(CLI::App& app);
void addCaptureCommand(CLI::App& app);
void addTraverseCommand(CLI::App& app);
void addMapCommand(CLI::App& app);
void addRunCommand(CLI::App& app);
void addPlanCommand(CLI::App& app);
void addSizeCommand(CLI::App& app);
void addExperimentCommands(CLI::App& app);

}  // namespace fvp::apps
