#include "urbanslam/slam/ScanReferences.h"

#include <algorithm>
#include <utility>

namespace urbanslam::slam {

namespace {

// Everything pointSetFromScan reads of a scan.
bool sameReturns(const io::LaserScan& a, const io::LaserScan& b) {
  return a.ranges == b.ranges && a.valid == b.valid && a.angle_min_rad == b.angle_min_rad &&
         a.angle_increment_rad == b.angle_increment_rad && a.max_range_m == b.max_range_m && a.sensor_pose.x == b.sensor_pose.x &&
         a.sensor_pose.y == b.sensor_pose.y && a.sensor_pose.phi == b.sensor_pose.phi;
}

}  // namespace

ScanReferences::ScanReferences(const alignment::ScanModelOptions& model, bool in_vehicle_frame, size_t capacity)
    : model_(model), in_vehicle_frame_(in_vehicle_frame), capacity_(std::max<size_t>(1, capacity)) {}

std::shared_ptr<const alignment::IndexedReference> ScanReferences::get(const io::LaserScan& scan) {
  for (auto it = kept_.begin(); it != kept_.end(); ++it) {
    if (!sameReturns(it->scan, scan)) continue;
    kept_.splice(kept_.begin(), kept_, it);
    ++hits_;
    return kept_.front().reference;
  }
  ++misses_;
  auto reference = std::make_shared<const alignment::IndexedReference>(alignment::pointSetFromScan(scan, model_, in_vehicle_frame_));
  kept_.push_front({scan, reference});
  if (kept_.size() > capacity_) kept_.pop_back();
  return reference;
}

}  // namespace urbanslam::slam
