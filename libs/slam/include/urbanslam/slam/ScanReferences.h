#pragma once
// The earlier side of the latest loop-closure alignments, kept with the scan each was built from:
// its points, the grid and kd-tree over them and their line normals (IndexedReference.h).
// Along a revisit consecutive keyframes try the same earlier keyframes, whose scans (their moving
// returns hidden, judged anew at each attempt) mostly come out the same; a reference is handed
// out again only for a scan equal to it, field by field, so an alignment is the same either way.
#include <cstddef>
#include <list>
#include <memory>

#include "urbanslam/alignment/IndexedReference.h"
#include "urbanslam/alignment/ScanModel.h"
#include "urbanslam/io/LaserScan.h"

namespace urbanslam::slam {

class ScanReferences {
 public:
  // The points of every scan asked for are taken with these options.
  ScanReferences(const alignment::ScanModelOptions& model, bool in_vehicle_frame, size_t capacity);
  // The scan's reference, built when no kept one is of an equal scan; the least recently used
  // is dropped beyond `capacity`.
  std::shared_ptr<const alignment::IndexedReference> get(const io::LaserScan& scan);
  size_t hits() const { return hits_; }
  size_t misses() const { return misses_; }

 private:
  struct Kept {
    io::LaserScan scan;
    std::shared_ptr<const alignment::IndexedReference> reference;
  };
  alignment::ScanModelOptions model_;
  bool in_vehicle_frame_;
  size_t capacity_;
  std::list<Kept> kept_;  // most recently used first
  size_t hits_ = 0, misses_ = 0;
};

}  // namespace urbanslam::slam
