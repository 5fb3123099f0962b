#include "urbanslam/slam/FreeSpaceCache.h"

#include <algorithm>
#include <limits>

#include "urbanslam/alignment/ScanModel.h"

namespace urbanslam::slam {

alignment::BeamFreeSpace scanFreeSpace(const io::LaserScan& scan, double margin_m, double margin_fraction) {
  alignment::ScanModelOptions model;  // every return the scan kept
  model.max_range_m = std::numeric_limits<double>::infinity();
  model.min_range_m = 0;
  return alignment::BeamFreeSpace(alignment::pointSetFromScan(scan, model, true), margin_m, margin_fraction);
}

FreeSpaceCache::FreeSpaceCache(double margin_m, double margin_fraction, size_t capacity)
    : margin_m_(margin_m), margin_fraction_(margin_fraction), capacity_(std::max<size_t>(1, capacity)) {}

const alignment::BeamFreeSpace* FreeSpaceCache::find(size_t key) {
  const auto it = index_.find(key);
  if (it == index_.end()) return nullptr;
  order_.splice(order_.begin(), order_, it->second);
  return &it->second->second;
}

const alignment::BeamFreeSpace& FreeSpaceCache::insert(size_t key, alignment::BeamFreeSpace free) {
  if (order_.size() >= capacity_) {
    index_.erase(order_.back().first);
    order_.pop_back();
  }
  order_.emplace_front(key, std::move(free));
  index_[key] = order_.begin();
  return order_.front().second;
}

void FreeSpaceCache::clear() {
  order_.clear();
  index_.clear();
}

}  // namespace urbanslam::slam
