#include "urbanslam/slam/KeyframeGrid.h"

#include <algorithm>
#include <cmath>

namespace urbanslam::slam {

int64_t KeyframeGrid::cell(double v) const {
  const double c = std::floor(v / cell_m_);
  if (!(c > -static_cast<double>(kMaxCell))) return -kMaxCell;  // also NaN
  if (c > static_cast<double>(kMaxCell)) return kMaxCell;
  return static_cast<int64_t>(c);
}

void KeyframeGrid::insert(size_t index, double x, double y) { cells_[key(cell(x), cell(y))].push_back(index); }

void KeyframeGrid::query(double x, double y, double radius, std::vector<size_t>& out) const {
  if (!(radius >= 0)) return;  // negative or NaN: no disk
  const int64_t x0 = cell(x - radius), x1 = cell(x + radius);
  const int64_t y0 = cell(y - radius), y1 = cell(y + radius);
  const double box = static_cast<double>(x1 - x0 + 1) * static_cast<double>(y1 - y0 + 1);
  if (box <= static_cast<double>(cells_.size())) {
    for (int64_t cx = x0; cx <= x1; ++cx)
      for (int64_t cy = y0; cy <= y1; ++cy) {
        const auto it = cells_.find(key(cx, cy));
        if (it != cells_.end()) out.insert(out.end(), it->second.begin(), it->second.end());
      }
    return;
  }
  // A box with more cells than are occupied (a huge radius): visit the occupied cells instead,
  // in the order the box walk would have used.
  std::vector<uint64_t> hits;
  for (const auto& [k, v] : cells_) {
    const int64_t cx = static_cast<int64_t>(k >> 32) - kMaxCell, cy = static_cast<int64_t>(k & 0xffffffffu) - kMaxCell;
    if (cx >= x0 && cx <= x1 && cy >= y0 && cy <= y1) hits.push_back(k);
  }
  std::sort(hits.begin(), hits.end());
  for (uint64_t k : hits) {
    const auto& v = cells_.at(k);
    out.insert(out.end(), v.begin(), v.end());
  }
}

}  // namespace urbanslam::slam
