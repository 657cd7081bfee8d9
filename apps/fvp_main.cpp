// fvp: command-line entry point. Options are parsed here; the work is in the libraries.
#include <exception>
#include <iostream>

#include "commands.h"

int main(int argc, char** argv) {
  CLI::App app{"fvp: apple-fruitlet sizing with next-best-view planning"};
  app.require_subcommand(1);
  fvp::apps::addBackendsCommand(app);
  fvp::apps::addCaptureCommand(app);
  fvp::apps::addTraverseCommand(app);
  fvp::apps::addMapCommand(app);
  fvp::apps::addRunCommand(app);
  fvp::apps::addPlanCommand(app);
  fvp::apps::addSizeCommand(app);
  fvp::apps::addExperimentCommands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::cerr << "fvp: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
