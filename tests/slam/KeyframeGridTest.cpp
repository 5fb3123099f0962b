#include "urbanslam/slam/KeyframeGrid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

using urbanslam::slam::KeyframeGrid;

namespace {
std::vector<size_t> near(const KeyframeGrid& g, double x, double y, double r) {
  std::vector<size_t> out;
  g.query(x, y, r, out);
  std::sort(out.begin(), out.end());
  return out;
}
}  // namespace

TEST(KeyframeGrid, FindsNeighboursAroundTheOriginAndNegativeCells) {
  KeyframeGrid g(10.0);
  g.insert(0, 1, 1);
  g.insert(1, -1, -1);
  g.insert(2, -25, 3);
  g.insert(3, 500, -500);
  EXPECT_EQ(near(g, 0, 0, 5), (std::vector<size_t>{0, 1}));
  EXPECT_EQ(near(g, -24, 2, 1), (std::vector<size_t>{2}));
  EXPECT_EQ(near(g, 500, -500, 1), (std::vector<size_t>{3}));
}

// Coordinates far beyond any map (a corrupt log) map to the border cells instead of
// out-of-range integer conversions; opposite extremes stay apart.
TEST(KeyframeGrid, AnyDoubleHasACell) {
  KeyframeGrid g(1.0);
  const double inf = std::numeric_limits<double>::infinity();
  g.insert(0, 1e300, 0);
  g.insert(1, -1e300, 0);
  g.insert(2, 0, -2147483649.0);
  g.insert(3, inf, -inf);
  g.insert(4, std::nan(""), 1e6);  // NaN shares a border cell; it only must not break the others
  EXPECT_EQ(near(g, 1e300, 0, 1), (std::vector<size_t>{0}));
  EXPECT_EQ(near(g, -1e300, 0, 1), (std::vector<size_t>{1}));
  EXPECT_EQ(near(g, 0, -2147483649.0, 1), (std::vector<size_t>{2}));
  EXPECT_TRUE(near(g, 0, 0, 1).empty());
  std::vector<size_t> out;
  g.query(0, 0, std::nan(""), out);
  EXPECT_TRUE(out.empty());
}

// A huge search radius (a pose whose uncertainty exploded) costs the occupied cells, not the
// cells of the box: this query covered 1e24 cells before.
TEST(KeyframeGrid, HugeRadiusQueriesFinishAtOnce) {
  KeyframeGrid g(5.0);
  for (size_t k = 0; k < 100; ++k) g.insert(k, static_cast<double>(k), -2147483649.0);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(near(g, 0, -2147483649.0, 1e12).size(), 100u);
  EXPECT_EQ(near(g, 0, 0, std::numeric_limits<double>::infinity()).size(), 100u);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
}
