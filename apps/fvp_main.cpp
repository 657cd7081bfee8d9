// fvp: command-line entry point. Options are parsed in cli.cpp; the work is in the libraries.
#include "commands.h"

int main(int argc, char** argv) {
  return fvp::apps::runFvp(argc, argv, fvp::apps::CliMode::kRun);
}
