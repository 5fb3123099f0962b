#pragma once
// Paths for tests: shipped data in the repo, the optional big datasets in ../shared/data, and a
// fresh scratch folder per test under the build tree.
#include <filesystem>
#include <string>

namespace urbanslam::test {

inline std::string repoPath(const std::string& rel) { return std::string(URBANSLAM_SOURCE_DIR) + "/" + rel; }

// Path of a file in ../shared/data, or "" when absent (the caller GTEST_SKIPs with a reason).
inline std::string sharedDataPath(const std::string& rel) {
  const std::string p = std::string(URBANSLAM_SHARED_DATA_DIR) + "/" + rel;
  return std::filesystem::exists(p) ? p : std::string();
}

// `name` must be unique to one test: ctest runs tests in parallel and this clears the folder.
inline std::filesystem::path scratchDir(const std::string& name) {
  const auto d = std::filesystem::path(URBANSLAM_BINARY_DIR) / "test_tmp" / name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

}  // namespace urbanslam::test
