#include "urbanslam/io/ScanStore.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace urbanslam::io {

namespace {

std::runtime_error spillError(const std::string& what, const std::string& dir) {
  return std::runtime_error("scan store: " + what + " the spill file in " + dir + ": " + std::strerror(errno));
}

}  // namespace

ScanStore::ScanStore(size_t cache_bytes, std::string spill_dir) : cache_bytes_(cache_bytes), spill_dir_(std::move(spill_dir)) {}

ScanStore::~ScanStore() {
  if (spill_fd_ >= 0) ::close(spill_fd_);
}

size_t ScanStore::add(CompactScan scan) {
  std::lock_guard<std::mutex> lock(mutex_);
  const size_t id = entries_.size();
  Entry e;
  e.valid = static_cast<std::uint32_t>(scan.validCount());
  e.bytes = static_cast<std::uint32_t>(scan.memoryBytes());
  entries_.push_back(e);
  holdLocked(id, std::make_shared<const CompactScan>(std::move(scan)));
  evictLocked();
  return id;
}

size_t ScanStore::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return entries_.size();
}

std::shared_ptr<const CompactScan> ScanStore::get(size_t id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  Entry& e = entries_.at(id);
  if (e.scan) {
    lru_.splice(lru_.begin(), lru_, e.lru);
    return e.scan;
  }
  auto scan = readBackLocked(e);
  holdLocked(id, scan);
  evictLocked();
  return scan;
}

void ScanStore::expandInto(size_t id, LaserScan& out) const { get(id)->expandInto(out); }

LaserScan ScanStore::expand(size_t id) const { return get(id)->expand(); }

size_t ScanStore::validCount(size_t id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return entries_.at(id).valid;
}

size_t ScanStore::residentBytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return resident_bytes_;
}

size_t ScanStore::spilledBytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return spill_end_;
}

void ScanStore::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  entries_.clear();
  lru_.clear();
  resident_bytes_ = 0;
  spill_end_ = 0;
  if (spill_fd_ >= 0 && ::ftruncate(spill_fd_, 0) != 0) {
    ::close(spill_fd_);  // a fresh file at the next spill
    spill_fd_ = -1;
  }
}

void ScanStore::holdLocked(size_t id, std::shared_ptr<const CompactScan> scan) const {
  Entry& e = entries_[id];
  e.scan = std::move(scan);
  lru_.push_front(id);
  e.lru = lru_.begin();
  resident_bytes_ += e.bytes;
}

void ScanStore::evictLocked() const {
  while (resident_bytes_ > cache_bytes_ && !lru_.empty()) {
    Entry& e = entries_[lru_.back()];
    // Written once: a scan never changes, so the copy on disk stays good for later evictions.
    if (e.length == 0) spillLocked(e);
    e.scan.reset();
    resident_bytes_ -= e.bytes;
    lru_.pop_back();
  }
}

void ScanStore::spillLocked(Entry& e) const {
  if (spill_fd_ < 0) openSpillFileLocked();
  common::BinaryWriter w;
  e.scan->write(w);
  const std::string& bytes = w.bytes();
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pwrite(spill_fd_, bytes.data() + done, bytes.size() - done, static_cast<off_t>(spill_end_ + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw spillError("cannot write", spill_dir_);
    done += static_cast<size_t>(n);
  }
  e.offset = spill_end_;
  e.length = static_cast<std::uint32_t>(bytes.size());
  spill_end_ += bytes.size();
}

std::shared_ptr<const CompactScan> ScanStore::readBackLocked(const Entry& e) const {
  std::string bytes(e.length, '\0');
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pread(spill_fd_, bytes.data() + done, bytes.size() - done, static_cast<off_t>(e.offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw spillError("cannot read back", spill_dir_);
    done += static_cast<size_t>(n);
  }
  common::BinaryReader r(bytes.data(), bytes.size(), "scan store spill file");
  auto scan = std::make_shared<const CompactScan>(CompactScan::read(r));
  r.expectEnd();
  return scan;
}

void ScanStore::openSpillFileLocked() const {
  if (spill_dir_.empty()) spill_dir_ = std::filesystem::temp_directory_path().string();
    // Unlinked from the start: nothing to clean up after a crash, nothing a run folder shows.
#ifdef O_TMPFILE
  spill_fd_ = ::open(spill_dir_.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
#endif
  if (spill_fd_ < 0) {
    // File systems without O_TMPFILE: a named file, unlinked as soon as it is open.
    std::string path = (std::filesystem::path(spill_dir_) / "urbanslam-scans-XXXXXX").string();
    spill_fd_ = ::mkostemp(path.data(), O_CLOEXEC);
    if (spill_fd_ < 0) throw spillError("cannot create", spill_dir_);
    ::unlink(path.c_str());
  }
}

}  // namespace urbanslam::io
