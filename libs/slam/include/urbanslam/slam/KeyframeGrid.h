#pragma once
// The map's spatial index: a uniform grid over keyframe positions, so the keyframes near a pose
// (the loop-closure candidates' initial set) are found in constant time however large the map.
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "urbanslam/common/BinaryStream.h"

namespace urbanslam::slam {

class KeyframeGrid {
 public:
  explicit KeyframeGrid(double cell_m) : cell_m_(cell_m) {}
  void clear() { cells_.clear(); }
  void insert(size_t index, double x, double y);
  // Indices of keyframes whose cell lies within `radius` of (x, y) (a superset of the disk).
  // Costs at most the number of occupied cells, however large the radius.
  void query(double x, double y, double radius, std::vector<size_t>& out) const;

  // The cells as they are (not rebuilt from the keyframes: between two reindex() calls a
  // keyframe stays in the cell of the pose it was inserted at). PipelineState.cpp.
  void writeState(common::BinaryWriter& w) const;
  void readState(common::BinaryReader& r, size_t keyframes);

 private:
  // Cell indices are clamped to +-2^30 so that any double (huge, infinite, NaN) has a cell and a
  // key: positions that far out share the border cells, which only costs the index precision.
  static constexpr int64_t kMaxCell = int64_t{1} << 30;
  int64_t cell(double v) const;
  static uint64_t key(int64_t cx, int64_t cy) {
    return (static_cast<uint64_t>(cx + kMaxCell) << 32) | static_cast<uint64_t>(cy + kMaxCell);
  }
  double cell_m_;
  std::unordered_map<uint64_t, std::vector<size_t>> cells_;
};

}  // namespace urbanslam::slam
