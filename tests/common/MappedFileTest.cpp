// A file read through MappedFile: its bytes, the pages given back as a reader passes them (read
// again from the file when a reader goes back), and the errors of what cannot be mapped.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/MappedFile.h"

namespace urbanslam::common {
namespace {

std::string tempPath(const std::string& name) { return (std::filesystem::temp_directory_path() / ("urbanslam_mapped_" + name)).string(); }

// Kilobytes of the mapping that starts at `start` resident in this process (/proc/self/smaps).
long residentKb(const void* start) {
  std::ifstream smaps("/proc/self/smaps");
  std::ostringstream want;
  want << std::hex << reinterpret_cast<std::uintptr_t>(start) << "-";
  bool in = false;
  for (std::string line; std::getline(smaps, line);) {
    if (line.rfind(want.str(), 0) == 0)
      in = true;
    else if (in && line.rfind("Rss:", 0) == 0)
      return std::stol(line.substr(4));
  }
  return -1;
}

// A reader with the file as its progress reads what the file holds while no more than about two
// stretches of it stay resident; pages given back are read again from the file.
TEST(MappedFile, AReaderLeavesAboutAStretchResidentAndPagesGivenBackReadAgain) {
  const std::string path = tempPath("bytes");
  constexpr size_t kStretch = size_t{4} << 20;  // (pages may come in 2 MB folios)
  std::string bytes(16 * kStretch + 12345, '\0');
  std::mt19937 rng(5);
  for (char& c : bytes) c = static_cast<char>(rng());
  {
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  MappedFile file(path, kStretch);
  ASSERT_EQ(file.size(), bytes.size());
  BinaryReader r(file.data(), file.size(), path, "corrupt", &file);
  std::string read(bytes.size(), '\0');
  long most = 0;
  for (size_t at = 0; at < bytes.size(); at += 4096) {
    r.raw(read.data() + at, std::min<size_t>(4096, bytes.size() - at));
    if (at % (kStretch / 4) == 0) most = std::max(most, residentKb(file.data()));
  }
  EXPECT_TRUE(read == bytes);
  EXPECT_GT(most, 0) << "the mapping was not found in /proc/self/smaps";
  EXPECT_LE(most, 3 * static_cast<long>(kStretch / 1024)) << "read pages were kept";
  // A pass of its own (as the checksum's) gives back what it read.
  file.release(file.data(), file.data() + file.size());
  EXPECT_LE(residentKb(file.data()), 8);
  EXPECT_EQ(std::string(file.data(), 64), bytes.substr(0, 64));
  EXPECT_EQ(std::string(file.data() + file.size() - 64, 64), bytes.substr(bytes.size() - 64));
  std::filesystem::remove(path);
}

TEST(MappedFile, AnEmptyFileHasNoBytesAndAMissingOneIsNamed) {
  const std::string path = tempPath("empty");
  { std::ofstream out(path); }
  EXPECT_EQ(MappedFile(path).size(), 0u);
  std::filesystem::remove(path);
  try {
    MappedFile missing(path);
    FAIL() << "a missing file was mapped";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_THROW(MappedFile(std::filesystem::temp_directory_path().string()), InputError);
}

}  // namespace
}  // namespace urbanslam::common
