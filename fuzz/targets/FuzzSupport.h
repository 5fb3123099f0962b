#pragma once
// Shared by the fuzz targets: readers that take a path get the input as a file, and an error is
// accepted only when it is the one clear line the CLI prints for bad input.
//
// Each target's LLVMFuzzerTestOneInput is built twice: with libFuzzer (clang, URBANSLAM_FUZZ=ON)
// and with RegressionMain.cpp in the normal build, which feeds it the regression corpus in ctest.
// Anything but success or a common::InputError that names the input aborts, which both count as
// a failure.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>

#include "urbanslam/common/Error.h"

namespace urbanslam::fuzz {

// A private folder for this process's input files (fuzzers run in parallel jobs).
inline const std::filesystem::path& scratchDir() {
  static const std::filesystem::path dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    auto d = std::filesystem::path(tmp && *tmp ? tmp : "/tmp") / ("urbanslam-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    // The folder goes with the process; a killed fuzzer leaves one small folder behind.
    static struct Cleanup {
      std::filesystem::path d;
      ~Cleanup() {
        std::error_code ec;
        std::filesystem::remove_all(d, ec);
      }
    } cleanup{d};
    return d;
  }();
  return dir;
}

// Writes the bytes to `name` in the scratch folder and returns its path.
inline std::string writeInput(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = (scratchDir() / name).string();
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) {
    std::perror(path.c_str());
    std::abort();
  }
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  return path;
}

inline std::string writeInput(const std::string& name, const std::string& bytes) {
  return writeInput(name, reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
}

[[noreturn]] inline void fail(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz target: %s: %s\n", what, detail.c_str());
  std::abort();
}

// Runs `body`; success and an InputError whose message is one line naming `name` are the only
// accepted outcomes (an empty `name`: any one line, for errors that name another file).
template <typename Body>
void expectCleanOutcome(const std::string& name, Body&& body) {
  try {
    body();
  } catch (const common::InputError& e) {
    const std::string msg = e.what();
    if (msg.empty()) fail("empty error message", name);
    if (msg.find(name) == std::string::npos) fail("error does not name the input", msg);
    if (msg.find('\n') != std::string::npos) fail("error is not one line", msg);
  } catch (const std::exception& e) {
    fail("not an input error", e.what());
  }
}

}  // namespace urbanslam::fuzz
