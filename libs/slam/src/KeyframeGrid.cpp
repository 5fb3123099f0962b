#include "urbanslam/slam/KeyframeGrid.h"

#include <cmath>

namespace urbanslam::slam {

void KeyframeGrid::insert(size_t index, double x, double y) {
  cells_[key(static_cast<long>(std::floor(x / cell_m_)), static_cast<long>(std::floor(y / cell_m_)))].push_back(index);
}

void KeyframeGrid::query(double x, double y, double radius, std::vector<size_t>& out) const {
  const long x0 = static_cast<long>(std::floor((x - radius) / cell_m_)), x1 = static_cast<long>(std::floor((x + radius) / cell_m_));
  const long y0 = static_cast<long>(std::floor((y - radius) / cell_m_)), y1 = static_cast<long>(std::floor((y + radius) / cell_m_));
  for (long cx = x0; cx <= x1; ++cx)
    for (long cy = y0; cy <= y1; ++cy) {
      const auto it = cells_.find(key(cx, cy));
      if (it != cells_.end()) out.insert(out.end(), it->second.begin(), it->second.end());
    }
}

}  // namespace urbanslam::slam
