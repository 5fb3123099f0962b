// urbanslam: one CLI, subcommands in the style of git (`urbanslam run LOG`, `urbanslam convert`).
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <string>

#include "Commands.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Heap.h"

namespace {

void printUsage() {
  std::cout << "usage: urbanslam <command> [options]\n\n"
               "Large-scale 2D SLAM from MRPT rawlogs, CARMEN and GMapping logs and the Victoria Park log.\n\n"
               "commands:\n";
  for (const auto& c : urbanslam::cli::commands()) {
    std::string n = std::string("  ") + c.name;
    n.resize(20, ' ');
    std::cout << n << c.summary << "\n";
  }
  std::cout << "\n`urbanslam <command> --help` describes each command.\n"
               "Exit codes: 0 success, 2 bad input (file, ini key, argument), 1 internal error.\n";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace urbanslam;
  common::keepFreedBuffers();
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") || !std::strcmp(argv[1], "help")) {
    printUsage();
    return argc < 2 ? common::kExitBadInput : 0;
  }
  if (!std::strcmp(argv[1], "--version")) {
    std::cout << "urbanslam " << URBANSLAM_VERSION << "\n";
    return 0;
  }
  const std::string name = argv[1];
  const cli::Argv args(argv + 2, argv + argc);
  for (const auto& c : cli::commands()) {
    if (name != c.name) continue;
    try {
      return c.run(args);
    } catch (const common::InputError& e) {
      std::fflush(stdout);
      std::cerr << "urbanslam " << name << ": error: " << e.what() << "\n";
      return common::kExitBadInput;
    } catch (const std::exception& e) {
      std::fflush(stdout);
      std::cerr << "urbanslam " << name << ": internal error: " << e.what() << "\n";
      return 1;
    }
  }
  std::cerr << "urbanslam: unknown command '" << name << "' (see urbanslam --help)\n";
  return common::kExitBadInput;
}
