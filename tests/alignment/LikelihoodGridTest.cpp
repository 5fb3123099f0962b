// The likelihood grid against its definition, cell by cell: a cell holds the log-likelihood of
// the nearest reference point among those whose stamp reaches it (the points whose cell lies
// within 3σ, rounded up to cells, on either axis), the floor where none does; a full-resolution
// level holds the exact largest value of its block, a coarser one a bound on it. The grid is
// built by spans of stamped columns and squared distances: the brute force here shares neither.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "urbanslam/alignment/LikelihoodGrid.h"

namespace urbanslam::alignment {
namespace {

// Clusters far apart (rows whose stamps lie at both ends), a slanted wall and lone points.
PointSet scatteredPoints() {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  PointSet out;
  const auto add = [&](double x, double y) {
    ScanPoint sp;
    sp.p = {x, y};
    out.push_back(sp);
  };
  for (int k = 0; k < 40; ++k) add(u(rng), u(rng));
  for (int k = 0; k <= 80; ++k) add(5.0 + 0.05 * k, 2.0 + 0.0063 * k);
  for (int k = 0; k < 10; ++k) add(-6.0 + u(rng), 7.0 + u(rng));
  add(3.0, -4.0);
  return out;
}

void expectMatchesDefinition(const LikelihoodGridOptions& o) {
  const PointSet pts = scatteredPoints();
  const LikelihoodGrid grid(pts, Eigen::Vector2d::Zero(), o);
  const int r = static_cast<int>(std::ceil(3.0 * o.hit_sigma_m / o.resolution_m));
  const float floor = static_cast<float>(std::log(o.miss_floor));
  // The grid tabulates the value over the squared distance, in 1024 steps up to the stamp's
  // corner: within one step's change of the value (its slope is at most 1/2σ²).
  const double table_step = 2.0 * (r + 1) * (r + 1) * o.resolution_m * o.resolution_m / 1024 / (2 * o.hit_sigma_m * o.hit_sigma_m);
  const Eigen::Vector2i lo = grid.cellOf({-8, -6}), hi = grid.cellOf({11, 10});
  int stamped = 0;
  for (int j = lo.y(); j <= hi.y(); ++j)
    for (int i = lo.x(); i <= hi.x(); ++i) {
      double best = -1e300;
      bool any = false;
      for (const auto& sp : pts) {
        const Eigen::Vector2i c = grid.cellOf(sp.p);
        if (std::abs(c.x() - i) > r || std::abs(c.y() - j) > r) continue;
        const double d2 = (grid.cellCentre(i, j) - sp.p).squaredNorm();
        best = std::max(best, std::log(std::exp(-d2 / (2 * o.hit_sigma_m * o.hit_sigma_m)) + o.miss_floor));
        any = true;
      }
      if (!any) {
        ASSERT_EQ(grid.value(0, i, j), floor) << i << "," << j;
        continue;
      }
      ++stamped;
      ASSERT_NEAR(grid.value(0, i, j), std::max<double>(floor, best), table_step) << i << "," << j;
    }
  EXPECT_GT(stamped, 1000);
  // Level h: the largest value of the block of 2^h cells from (i, j), exactly at full
  // resolution, at least that above it; for the blocks a search asks (starting at most pad()
  // cells before cell 0).
  for (int h = 1; h <= grid.levels(); ++h) {
    const int n = 1 << h;
    for (int j = std::max(lo.y(), -grid.pad()); j <= hi.y(); j += 3)
      for (int i = std::max(lo.x(), -grid.pad()); i <= hi.x(); i += 3) {
        float block = floor;
        for (int b = 0; b < n; ++b)
          for (int a = 0; a < n; ++a) block = std::max(block, grid.value(0, i + a, j + b));
        if (grid.shiftOf(h) == 0)
          ASSERT_EQ(grid.value(h, i, j), block) << "level " << h << " at " << i << "," << j;
        else
          ASSERT_GE(grid.value(h, i, j), block) << "level " << h << " at " << i << "," << j;
      }
  }
}

TEST(LikelihoodGrid, CellsAndLevelsMatchTheirDefinition) {
  LikelihoodGridOptions o;  // local SLAM's: 5 cm, σ 5 cm, two full-resolution levels
  expectMatchesDefinition(o);
}

TEST(LikelihoodGrid, CoarseGridWithFourFullResolutionLevels) {
  LikelihoodGridOptions o;  // the place search's
  o.resolution_m = 0.1;
  o.hit_sigma_m = 0.1;
  o.full_resolution_levels = 4;
  expectMatchesDefinition(o);
}

// A grid's storage is reused by the next grid of the thread with only the cells it wrote reset:
// a grid built after a larger one that stamped nearly every cell (other points, another origin,
// wider rows) holds no trace of it.
TEST(LikelihoodGrid, AGridBuiltAfterALargerOneHoldsNoTraceOfIt) {
  LikelihoodGridOptions o;
  for (int round = 0; round < 2; ++round) {
    {
      std::mt19937 rng(5 + round);
      std::uniform_real_distribution<double> x(-10.0, 13.0), y(-8.0, 12.0);
      PointSet dense(60000);
      for (auto& sp : dense) sp.p = {x(rng), y(rng)};
      const LikelihoodGrid larger(dense, Eigen::Vector2d(1.0, 0.5), o);
      ASSERT_GT(larger.score({0.3, 0.3}), larger.floorValue());
    }
    expectMatchesDefinition(o);
  }
}

TEST(LikelihoodGrid, PointsBeyondTheRadiusLeaveTheFloor) {
  LikelihoodGridOptions o;
  o.max_radius_m = 2.0;
  const PointSet pts = scatteredPoints();
  const LikelihoodGrid grid(pts, Eigen::Vector2d::Zero(), o);
  EXPECT_GT(grid.score({0.0, 0.0}), grid.floorValue());
  EXPECT_EQ(grid.score({6.0, 2.0}), grid.floorValue());  // the wall lies beyond 2 m
}

}  // namespace
}  // namespace urbanslam::alignment
