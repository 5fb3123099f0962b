#pragma once
// A file a process writes for itself alone: bytes that would otherwise stay in memory for the
// whole run (scans pushed out of a cache, the older part of a log that only grows), appended
// once and read back by offset. It is created unlinked in its folder (the system's temporary
// folder by default) at the first append, so it vanishes with its owner or with a killed
// process and never mixes with a run's outputs. Reads and writes use explicit offsets, so
// concurrent reads need no lock; appends must not race with each other.
#include <cstdint>
#include <string>

namespace urbanslam::io {

class ScratchFile {
 public:
  // `owner` names the file in error messages ("scan store"); `dir` empty: the system's
  // temporary folder.
  ScratchFile(std::string owner, std::string dir);
  ~ScratchFile();
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;

  // Appends `bytes`; returns the offset they start at. Throws std::runtime_error naming the
  // owner and the folder when the file cannot be created or written.
  std::uint64_t append(const std::string& bytes);
  // `length` bytes from `offset`; throws std::runtime_error when they cannot be read.
  std::string read(std::uint64_t offset, size_t length) const;
  // Bytes appended so far.
  std::uint64_t size() const { return end_; }
  // Drops every byte (the next append starts at offset 0).
  void clear();

 private:
  std::string owner_;
  std::string dir_;  // resolved at the first append
  int fd_ = -1;
  std::uint64_t end_ = 0;
};

}  // namespace urbanslam::io
