// The city's geometry: ray casting against analytic ranges and a brute-force reference, and
// tiles that are a pure function of (seed, tile index).
#include <gtest/gtest.h>

#include <cmath>

#include "urbanslam/sim/CityModel.h"
#include "urbanslam/sim/LaserSimulator.h"
#include "urbanslam/sim/Random.h"

using namespace urbanslam;
using namespace urbanslam::sim;

namespace {

CityOptions smallCity() {
  CityOptions o;
  o.seed = 7;
  o.area_km2 = 0.5;
  o.cache_tiles = 9;
  return o;
}

double bruteForce(const std::vector<Segment>& segs, Vec2 o, Vec2 d, double max_range) {
  double best = kNoHit;
  for (const Segment& s : segs) best = std::min(best, raySegment(o, d, s));
  return best <= max_range ? best : kNoHit;
}

}  // namespace

TEST(RaySegment, HitsAWallAtTheAnalyticRange) {
  // A wall x = 10, |y| <= 5: a beam at angle a from the origin meets it at 10 / cos(a).
  const Segment wall{{10, -5}, {10, 5}};
  for (double a = -0.4; a <= 0.4; a += 0.05) EXPECT_NEAR(raySegment({0, 0}, {std::cos(a), std::sin(a)}, wall), 10 / std::cos(a), 1e-9) << a;
  EXPECT_EQ(raySegment({0, 0}, {std::cos(0.6), std::sin(0.6)}, wall), kNoHit);  // passes above its end
  EXPECT_EQ(raySegment({0, 0}, {-1, 0}, wall), kNoHit);                         // behind the sensor
}

TEST(CityModel, RaycastEqualsBruteForceOverAllNearbyWalls) {
  const CityModel city(smallCity());
  const auto& g = city.streets();
  Rng rng(3);
  int hits = 0;
  for (int k = 0; k < 400; ++k) {
    // Origins in the streets (and anywhere else: inside blocks must work too), rays in all directions.
    const Vec2 o = k % 2 ? g.node({rng.uniformInt(0, g.lineCount() - 1), rng.uniformInt(0, g.lineCount() - 1)})
                         : Vec2{rng.uniform(0, 700), rng.uniform(0, 700)};
    const double a = rng.uniform(-M_PI, M_PI);
    const Vec2 d{std::cos(a), std::sin(a)};
    const double max_range = 90;
    const auto segs = city.segmentsNear({o.x - max_range, o.y - max_range, o.x + max_range, o.y + max_range});
    const double expected = bruteForce(segs, o, d, max_range);
    const double got = city.raycast(o, d, max_range);
    if (expected == kNoHit) {
      EXPECT_EQ(got, kNoHit) << k;
    } else {
      EXPECT_NEAR(got, expected, 1e-9) << k;
    }
    hits += expected != kNoHit;
  }
  EXPECT_GT(hits, 200);  // the test is about walls actually being hit
}

TEST(CityModel, TilesAreIdenticalWhateverWasBuiltBefore) {
  const CityModel a(smallCity()), b(smallCity());
  // a: the tile first; b: its neighbours first, then enough other tiles to evict everything.
  const auto ta = a.tile(1, 1);
  const std::vector<Segment> first = ta->segments;
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy) b.tile(1 + dx, 1 + dy);
  for (int k = 0; k < 30; ++k) b.tile(5 + k, -3);
  EXPECT_EQ(b.tilesCached(), 9u);
  const auto tb = b.tile(1, 1);  // rebuilt after eviction
  ASSERT_EQ(first.size(), tb->segments.size());
  ASSERT_GT(first.size(), 100u);
  for (size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(first[i].a.x, tb->segments[i].a.x);
    EXPECT_EQ(first[i].a.y, tb->segments[i].a.y);
    EXPECT_EQ(first[i].b.x, tb->segments[i].b.x);
    EXPECT_EQ(first[i].b.y, tb->segments[i].b.y);
  }
  // Locality: every segment lies inside its tile.
  for (const Segment& s : first)
    for (Vec2 p : {s.a, s.b}) EXPECT_TRUE(ta->box.contains(p));
}

TEST(CityModel, DifferentSeedsGiveDifferentCities) {
  CityOptions o = smallCity();
  const CityModel a(o);
  o.seed = 8;
  const CityModel b(o);
  const auto sa = a.tile(1, 1)->segments, sb = b.tile(1, 1)->segments;
  const bool same = sa.size() == sb.size() && sa[0].a.x == sb[0].a.x && sa[0].a.y == sb[0].a.y;
  EXPECT_FALSE(same);
}

TEST(StreetGrid, BlocksStayWithinTheirSizeLimitsAndNodesKeepThreeWaysOut) {
  const StreetGrid g(smallCity());
  const auto& o = g.options();
  for (int i = -1; i < g.lineCount(); ++i) {
    const Box b = g.block(i, 0);
    EXPECT_GE(b.x1 - b.x0, o.block_min_m - 1e-9);
    EXPECT_LE(b.x1 - b.x0, o.block_max_m + 1e-9);
    EXPECT_EQ(g.lineBelow(0, g.linePos(0, i) + 1e-6), i);
  }
  for (int i = 1; i + 1 < g.lineCount(); ++i)
    for (int j = 1; j + 1 < g.lineCount(); ++j) EXPECT_GE(g.neighbours({i, j}).size(), 3u);
}

TEST(LaserSimulator, NoiselessBeamsMatchBruteForceRayCasting) {
  const CityModel city(smallCity());
  LaserOptions lo;
  lo.range_sigma_m = 0;
  lo.range_sigma_per_m = 0;
  lo.dropout_probability = 0;
  lo.fov_deg = 360;
  lo.angular_resolution_deg = 1.0;
  const LaserSimulator laser(lo, city, nullptr, 1);
  ASSERT_EQ(laser.beams(), 360u);
  const common::Pose2 vehicle{city.streets().node({2, 2}).x, city.streets().node({2, 2}).y + 20, 0.3};
  const io::LaserScan s = laser.scan(0, 0, 0, vehicle);
  const common::Pose2 sensor = common::compose(vehicle, s.sensor_pose);
  const auto segs = city.segmentsNear({sensor.x - 90, sensor.y - 90, sensor.x + 90, sensor.y + 90});
  size_t valid = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    const double a = sensor.phi + s.bearing(i);
    const double expected = bruteForce(segs, {sensor.x, sensor.y}, {std::cos(a), std::sin(a)}, lo.max_range_m);
    ASSERT_EQ(s.valid[i] != 0, expected < lo.max_range_m) << i;
    if (s.valid[i]) {
      EXPECT_NEAR(s.ranges[i], expected, 1e-4) << i;
    }
    valid += s.valid[i];
  }
  EXPECT_GT(valid, 300u);
}
