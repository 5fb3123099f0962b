#pragma once
// The sections of a map file's payload by tag (the layout of libs/slam/README.md), for tests that
// compare two saved states section by section.
#include <cstdint>
#include <map>
#include <string>

namespace urbanslam::test {

inline std::map<std::string, std::string> mapFileSections(const std::string& file) {
  std::map<std::string, std::string> out;
  for (size_t at = 28; at + 12 <= file.size();) {
    uint64_t length = 0;
    for (int i = 7; i >= 0; --i) length = length << 8 | static_cast<unsigned char>(file[at + 4 + static_cast<size_t>(i)]);
    out[file.substr(at, 4)] = file.substr(at + 12, length);
    at += 12 + length;
  }
  return out;
}

}  // namespace urbanslam::test
