#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <utility>

#include "urbanslam/alignment/Voxels.h"

using namespace urbanslam;

// Against a brute-force reference: walking the points in order, a point is kept exactly when no
// earlier point lies in its voxel (the voxel of (x, y) is (floor(x / v), floor(y / v))).
TEST(Voxels, TheFirstPointOfEachVoxelInTheSetsOrder) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-60, 60);
  for (const double v : {0.05, 0.2, 0.3, 1.0}) {
    alignment::PointSet points(3000);
    for (auto& p : points) p.p = {u(rng), u(rng)};
    for (size_t i = 0; i < 500; ++i) points.push_back(points[i * 3]);  // repeated points
    std::vector<size_t> expected;
    std::set<std::pair<long long, long long>> seen;
    for (size_t i = 0; i < points.size(); ++i) {
      const auto key =
          std::make_pair(static_cast<long long>(std::floor(points[i].p.x() / v)), static_cast<long long>(std::floor(points[i].p.y() / v)));
      if (seen.insert(key).second) expected.push_back(i);
    }
    EXPECT_EQ(alignment::firstPerVoxel(points, v), expected) << v;
  }
  EXPECT_TRUE(alignment::firstPerVoxel({}, 0.2).empty());
}
