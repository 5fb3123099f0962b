#pragma once
// The free space of scans that judge others (which of another scan's points they saw through),
// kept for the scans used lately, least recently used dropped: judging keyframe after keyframe,
// consecutive ones share most of their judges. The exported clouds' moving points (MovingPoints.h)
// and a loop closure's moving returns (MovingReturns.h) keep one each.
#include <cstddef>
#include <list>
#include <unordered_map>
#include <utility>

#include "urbanslam/alignment/BeamFreeSpace.h"
#include "urbanslam/io/LaserScan.h"

namespace urbanslam::slam {

// A scan's free space in its vehicle frame, every return it kept (no range gate): a point
// conflicts margin_m + margin_fraction × range in front of its bearing's returns.
alignment::BeamFreeSpace scanFreeSpace(const io::LaserScan& scan, double margin_m, double margin_fraction);

class FreeSpaceCache {
 public:
  FreeSpaceCache(double margin_m, double margin_fraction, size_t capacity);
  // The free space of the scan `key` names, built from `scan(buffer)` (a const io::LaserScan&,
  // the scan itself or expanded into the buffer) when it is not kept. The reference stays valid
  // until `capacity` other keys have been asked for.
  template <class ScanOf>
  const alignment::BeamFreeSpace& get(size_t key, ScanOf&& scan) {
    if (const alignment::BeamFreeSpace* kept = find(key)) return *kept;
    return insert(key, scanFreeSpace(scan(buffer_), margin_m_, margin_fraction_));
  }
  void clear();

 private:
  const alignment::BeamFreeSpace* find(size_t key);  // and makes it the most recently used
  const alignment::BeamFreeSpace& insert(size_t key, alignment::BeamFreeSpace free);

  double margin_m_, margin_fraction_;
  size_t capacity_;
  io::LaserScan buffer_;
  std::list<std::pair<size_t, alignment::BeamFreeSpace>> order_;  // most recently used first
  std::unordered_map<size_t, std::list<std::pair<size_t, alignment::BeamFreeSpace>>::iterator> index_;
};

}  // namespace urbanslam::slam
