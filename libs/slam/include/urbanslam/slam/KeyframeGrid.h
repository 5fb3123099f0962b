#pragma once
// The map's spatial index: a uniform grid over keyframe positions, so the keyframes near a pose
// (the loop-closure candidates' initial set) are found in constant time however large the map.
#include <cstddef>
#include <unordered_map>
#include <vector>

namespace urbanslam::slam {

class KeyframeGrid {
 public:
  explicit KeyframeGrid(double cell_m) : cell_m_(cell_m) {}
  void clear() { cells_.clear(); }
  void insert(size_t index, double x, double y);
  // Indices of keyframes whose cell lies within `radius` of (x, y) (a superset of the disk).
  void query(double x, double y, double radius, std::vector<size_t>& out) const;

 private:
  long long key(long cx, long cy) const { return (static_cast<long long>(cx) << 32) ^ (cy & 0xffffffffLL); }
  double cell_m_;
  std::unordered_map<long long, std::vector<size_t>> cells_;
};

}  // namespace urbanslam::slam
