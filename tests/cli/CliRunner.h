#pragma once
// Runs the urbanslam executable and captures exit code, stdout and stderr.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "TestPaths.h"

namespace urbanslam::test {

struct CliResult {
  int code = -1;
  std::string out, err;
};

inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// `args` is passed to /bin/sh: quote paths with spaces. `shell_prefix` runs first in the same
// shell (e.g. "ulimit -v 1000000;").
inline CliResult runCliAfter(const std::string& shell_prefix, const std::string& args) {
  const auto dir = std::filesystem::path(URBANSLAM_BINARY_DIR) / "test_tmp";
  std::filesystem::create_directories(dir);
  // Unique names: ctest runs test cases of this executable in parallel processes.
  static int counter = 0;
  const std::string stem = "cli_" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
  const std::string out = (dir / (stem + ".out")).string(), err = (dir / (stem + ".err")).string();
  const std::string cmd = shell_prefix + std::string(URBANSLAM_CLI) + " " + args + " >" + out + " 2>" + err + " </dev/null";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return r;
}

inline CliResult runCli(const std::string& args) { return runCliAfter("", args); }

}  // namespace urbanslam::test
