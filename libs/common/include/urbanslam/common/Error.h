#pragma once
// Errors that the user can fix (bad file, bad ini key, bad argument). The CLI turns them into
// one clear line on stderr and exit code 2; anything else is a bug and exits with 1.
#include <stdexcept>
#include <string>

namespace urbanslam::common {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& what) : std::runtime_error(what) {}
};

// Configuration errors name the file, section and key, e.g. "ini/x.ini: [map] resolution_m: ...".
class ConfigError : public InputError {
 public:
  using InputError::InputError;
};

// Exit code of the CLI for bad input.
constexpr int kExitBadInput = 2;

}  // namespace urbanslam::common
