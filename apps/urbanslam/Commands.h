#pragma once
// The subcommands of `urbanslam`. Each lives in its own <Name>Command.cpp, parses its own
// arguments with ArgParser, prints results (one JSON object on stdout with --json), and returns
// the process exit code. common::InputError escaping a command becomes one error line + exit 2.
#include <string>
#include <vector>

namespace urbanslam::cli {

using Argv = std::vector<std::string>;

struct Command {
  const char* name;
  const char* summary;
  int (*run)(const Argv& args);
};

int runCommand(const Argv& args);
int localizeCommand(const Argv& args);
int mergeCommand(const Argv& args);
int convertCommand(const Argv& args);
int checkIniCommand(const Argv& args);
int evalCommand(const Argv& args);
int graphCommand(const Argv& args);
int alignCommand(const Argv& args);
int trainLaserLoopCommand(const Argv& args);
int evalLaserLoopCommand(const Argv& args);
int buildVocabularyCommand(const Argv& args);
int evalImageLoopCommand(const Argv& args);
int simulateCommand(const Argv& args);

// Every registered subcommand, in the order `urbanslam --help` lists them.
const std::vector<Command>& commands();

}  // namespace urbanslam::cli
