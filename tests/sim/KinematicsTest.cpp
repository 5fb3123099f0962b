// Vehicle motion: the bicycle model against the closed-form circle, and the driver keeping the
// car on the streets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "urbanslam/sim/Bicycle.h"
#include "urbanslam/sim/Driver.h"

using namespace urbanslam;
using namespace urbanslam::sim;

TEST(Bicycle, ConstantSteeringDrivesTheClosedFormCircle) {
  const double L = 2.7, v = 5.0, delta = 0.2, dt = 0.013;
  const common::Pose2 p0{3.0, -1.0, 0.4};
  const double R = L / std::tan(delta), w = v / R;
  const Vec2 c{p0.x - R * std::sin(p0.phi), p0.y + R * std::cos(p0.phi)};
  common::Pose2 p = p0;
  for (int k = 1; k <= 2000; ++k) {
    p = stepBicycle(p, v, delta, dt, L);
    const double th = p0.phi + w * k * dt;
    ASSERT_NEAR(p.x, c.x + R * std::sin(th), 1e-7) << k;
    ASSERT_NEAR(p.y, c.y - R * std::cos(th), 1e-7) << k;
    ASSERT_NEAR(common::wrapToPi(p.phi - th), 0.0, 1e-9) << k;
  }
  // Straight: no steering, a straight line.
  const common::Pose2 s = stepBicycle(p0, v, 0.0, 2.0, L);
  EXPECT_NEAR(s.x, p0.x + 10 * std::cos(0.4), 1e-12);
  EXPECT_NEAR(s.y, p0.y + 10 * std::sin(0.4), 1e-12);
}

TEST(Driver, StaysInTheRightLaneOfOpenStreetsAndSlowsForTurns) {
  SimOptions o;
  o.city.area_km2 = 0.5;
  o.route.route_length_km = 2.0;
  const StreetGrid g(o.city);
  Driver d(g, o);
  double t = 0, max_speed = 0, min_speed = 1e9;
  int samples = 0;
  while (!d.finished() && t < 1000) {
    t += 0.2;
    d.advanceTo(t);
    const auto& s = d.state();
    const Vec2 p{s.pose.x, s.pose.y};
    // Never inside a block's lot (the rear axle stays on the road).
    for (int i = -1; i < g.lineCount(); ++i)
      for (int j = -1; j < g.lineCount(); ++j) ASSERT_FALSE(g.block(i, j).contains(p)) << t;
    // Within a lane's width of the nearest street's centre line, mostly on its right side.
    const int i = g.lineBelow(0, p.x), j = g.lineBelow(1, p.y);
    const double dx = std::min(p.x - g.linePos(0, i), g.linePos(0, i + 1) - p.x);
    const double dy = std::min(p.y - g.linePos(1, j), g.linePos(1, j + 1) - p.y);
    EXPECT_LT(std::min(dx, dy), g.streetWidth() / 2) << t;
    if (t > 10) {
      max_speed = std::max(max_speed, s.speed_mps);
      min_speed = std::min(min_speed, s.speed_mps);
    }
    ++samples;
  }
  EXPECT_TRUE(d.finished());
  EXPECT_NEAR(max_speed, o.route.speed_mps, 0.5);
  EXPECT_LT(min_speed, o.route.turn_speed_mps + 1.0);
  EXPECT_GT(samples, 100);
}

// Another route seed drives another way through the same city, from the same start; route seed
// 0 is the city's own seed.
TEST(Driver, AnotherRouteSeedDrivesAnotherWayThroughTheSameCity) {
  SimOptions o;
  o.city.area_km2 = 0.5;
  o.city.seed = 3;
  o.route.route_length_km = 1.0;
  const StreetGrid g(o.city);
  const auto drive = [&](int route_seed) {
    SimOptions r = o;
    r.route.seed = route_seed;
    Driver d(g, r);
    std::vector<common::Pose2> poses;
    for (double t = 0; !d.finished() && t < 1000; t += 1.0) {
      d.advanceTo(t);
      poses.push_back(d.state().pose);
    }
    return poses;
  };
  const auto own = drive(0), same = drive(3), other = drive(4);
  ASSERT_EQ(own.size(), same.size());
  for (size_t i = 0; i < own.size(); ++i) ASSERT_EQ(own[i].x, same[i].x) << i;
  ASSERT_GT(other.size(), 10u);
  // The same intersection to start from (heading to a neighbour the route picks).
  EXPECT_LT(std::hypot(own[0].x - other[0].x, own[0].y - other[0].y), g.streetWidth());
  double apart = 0;
  for (size_t i = 0; i < std::min(own.size(), other.size()); ++i) apart = std::max(apart, std::hypot(own[i].x - other[i].x, own[i].y - other[i].y));
  EXPECT_GT(apart, 100.0);
}
