#pragma once
// Every keyframe scan of a map, in memory up to a bound and on disk beyond it. A city of 10^6
// keyframes holds close to a gigabyte of compact scans, yet a step only reads the few scans
// its loop candidates name: the most recently used scans stay in memory (at most
// cache_bytes), and a scan pushed out is written once to a spill file and read back from it
// when asked for again. Memory is then bounded by the cache and a small index entry per scan,
// whatever the map's size.
//
// The spill file is scratch: it is created unlinked in the spill folder (the system's
// temporary folder by default), so it vanishes with the store or with a killed process and
// never mixes with a run's outputs. The store is thread-safe: a scan handed out stays valid
// for as long as its holder keeps it, whatever is evicted meanwhile.
#include <cstdint>
#include <deque>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "urbanslam/io/CompactScan.h"
#include "urbanslam/io/ScratchFile.h"

namespace urbanslam::io {

class ScanStore {
 public:
  // `cache_bytes`: the bound on the scans held in memory (0: keep none but the one asked for).
  // `spill_dir`: where the spill file goes; empty for the system's temporary folder.
  explicit ScanStore(size_t cache_bytes = kDefaultCacheBytes, std::string spill_dir = {});
  ~ScanStore();
  ScanStore(const ScanStore&) = delete;
  ScanStore& operator=(const ScanStore&) = delete;

  static constexpr size_t kDefaultCacheBytes = size_t{256} << 20;

  // Adds a scan; returns its id (0, 1, 2, ... in the order added).
  size_t add(CompactScan scan);
  size_t size() const;

  // The scan `id`, from memory or read back from the spill file. Throws std::runtime_error when
  // the spill file cannot be read back (the disk failed under the run).
  std::shared_ptr<const CompactScan> get(size_t id) const;
  // get(id) expanded into `out` (reusing its buffers).
  void expandInto(size_t id, LaserScan& out) const;
  LaserScan expand(size_t id) const;
  // Beams flagged valid in scan `id`, without reading it back.
  size_t validCount(size_t id) const;

  // Bytes of the scans in memory now, and of those written to the spill file so far.
  size_t residentBytes() const;
  size_t spilledBytes() const;
  size_t cacheBytes() const { return cache_bytes_; }
  // Drops every scan (the spill file is truncated).
  void clear();

 private:
  struct Entry {
    std::shared_ptr<const CompactScan> scan;  // null when only on disk
    std::list<size_t>::iterator lru;          // its place in lru_ while in memory
    std::uint64_t offset = 0;                 // in the spill file, once written
    std::uint32_t length = 0;                 // 0: not written yet
    std::uint32_t valid = 0;                  // validCount()
    std::uint32_t bytes = 0;                  // memory it takes while held
  };

  void holdLocked(size_t id, std::shared_ptr<const CompactScan> scan) const;
  void evictLocked() const;
  void spillLocked(Entry& e) const;
  std::shared_ptr<const CompactScan> readBackLocked(const Entry& e) const;

  size_t cache_bytes_;
  mutable std::mutex mutex_;
  // One per scan, up to millions: grown by fixed blocks (a vector's doubling leaves up to half
  // its capacity unused and holds three times its size while it moves).
  mutable std::deque<Entry> entries_;
  mutable std::list<size_t> lru_;  // ids in memory, most recently used first
  mutable size_t resident_bytes_ = 0;
  mutable ScratchFile spill_;
};

}  // namespace urbanslam::io
