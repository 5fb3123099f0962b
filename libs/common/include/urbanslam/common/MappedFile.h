#pragma once
// A file mapped read-only into memory, whose pages can be given back once read. A map of a
// million keyframes is gigabytes: read whole into the heap, a checkpoint's load held it beside
// the map it built from it, twice the memory of the run. Mapped, the pages a BinaryReader has
// passed are dropped as it goes (they are the file's: reading them again reads the file), so
// the load holds about the map it builds.
#include <cstddef>
#include <string>

#include "urbanslam/common/BinaryStream.h"

namespace urbanslam::common {

class MappedFile : public ReadProgress {
 public:
  static constexpr size_t kDefaultStretchBytes = size_t{64} << 20;
  // Throws InputError naming the path when it cannot be opened or mapped. An empty file maps to
  // no bytes. A reader with this file as its ReadProgress leaves about `stretch_bytes` read and
  // not given back (up to twice that).
  explicit MappedFile(const std::string& path, size_t stretch_bytes = kDefaultStretchBytes);
  ~MappedFile() override;
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  const char* data() const { return data_; }
  size_t size() const { return size_; }
  size_t stretchBytes() const { return stretch_; }
  // The whole pages within [from, to) are given back (a pass of its own, as the checksum's).
  void release(const char* from, const char* to);
  // ReadProgress: a reader passed p; what lies a stretch or more behind it goes.
  void reached(const unsigned char* p) override;

 private:
  char* data_ = nullptr;
  size_t size_ = 0, stretch_ = kDefaultStretchBytes;
  const char* reader_released_ = nullptr;  // the reader's pass gave back everything before this
};

}  // namespace urbanslam::common
