#include "urbanslam/io/ScanStore.h"

#include <stdexcept>

namespace urbanslam::io {

ScanStore::ScanStore(size_t cache_bytes, std::string spill_dir) : cache_bytes_(cache_bytes), spill_("scan store", std::move(spill_dir)) {}

ScanStore::~ScanStore() = default;

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
  return spill_.size();
}

void ScanStore::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  entries_.clear();
  lru_.clear();
  resident_bytes_ = 0;
  spill_.clear();
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
  common::BinaryWriter w;
  e.scan->write(w);
  e.offset = spill_.append(w.bytes());
  e.length = static_cast<std::uint32_t>(w.bytes().size());
}

std::shared_ptr<const CompactScan> ScanStore::readBackLocked(const Entry& e) const {
  const std::string bytes = spill_.read(e.offset, e.length);
  common::BinaryReader r(bytes.data(), bytes.size(), "scan store spill file");
  auto scan = std::make_shared<const CompactScan>(CompactScan::read(r));
  r.expectEnd();
  return scan;
}

}  // namespace urbanslam::io
