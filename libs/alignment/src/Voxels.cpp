#include "urbanslam/alignment/Voxels.h"

#include <cmath>

namespace urbanslam::alignment {

// The voxels seen are kept in an open-addressing table of twice the points: every scan of local
// SLAM is thinned, and a node-based set would allocate once per voxel.
std::vector<size_t> firstPerVoxel(const PointSet& points, double voxel_m) {
  std::vector<size_t> out;
  size_t capacity = 16;
  while (capacity < 2 * points.size()) capacity *= 2;
  std::vector<unsigned long long> keys(capacity);
  std::vector<char> used(capacity, 0);
  for (size_t i = 0; i < points.size(); ++i) {
    const auto& p = points[i].p;
    const long long vx = static_cast<long long>(std::floor(p.x() / voxel_m));
    const long long vy = static_cast<long long>(std::floor(p.y() / voxel_m));
    // Shifted unsigned: a left shift of a negative value is undefined behaviour.
    const unsigned long long key = (static_cast<unsigned long long>(vx) << 32) ^ static_cast<unsigned long long>(vy & 0xffffffffLL);
    size_t slot = static_cast<size_t>((key * 0x9E3779B97F4A7C15ULL) >> 20) & (capacity - 1);
    while (used[slot] && keys[slot] != key) slot = (slot + 1) & (capacity - 1);
    if (used[slot]) continue;
    used[slot] = 1;
    keys[slot] = key;
    out.push_back(i);
  }
  return out;
}

}  // namespace urbanslam::alignment
