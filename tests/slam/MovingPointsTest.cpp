#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include "urbanslam/io/MapOutputs.h"
#include "urbanslam/slam/MovingPoints.h"

using namespace urbanslam;

namespace {

struct Segment {
  double x1, y1, x2, y2;
  bool moving;
};

// A room 20 m x 16 m, and a 1 m box that stands in it for the first scans only (or always).
std::vector<Segment> world(bool with_box) {
  std::vector<Segment> w = {{-10, -8, 10, -8, false}, {10, -8, 10, 8, false}, {10, 8, -10, 8, false}, {-10, 8, -10, -8, false}};
  if (with_box) {
    const double x0 = 3, x1 = 4, y0 = -0.5, y1 = 0.5;
    for (const Segment& s :
         std::vector<Segment>{{x0, y0, x1, y0, true}, {x1, y0, x1, y1, true}, {x1, y1, x0, y1, true}, {x0, y1, x0, y0, true}})
      w.push_back(s);
  }
  return w;
}

// A front 180° scan at half a degree from a sensor 0.5 m ahead of the vehicle, cast against the
// segments with 1 cm range noise; `hits_box` says per beam whether it ended on the box.
io::LaserScan castScan(const common::Pose2& vehicle, const std::vector<Segment>& w, std::mt19937& rng, std::vector<bool>& hits_box) {
  io::LaserScan s;
  s.angle_min_rad = -M_PI / 2;
  s.angle_increment_rad = M_PI / 360;
  s.max_range_m = 40;
  s.sensor_pose = {0.5, 0, 0};
  const common::Pose2 sensor = common::compose(vehicle, s.sensor_pose);
  std::normal_distribution<double> noise(0, 0.01);
  hits_box.clear();
  for (int i = 0; i <= 360; ++i) {
    const double a = sensor.phi + s.bearing(static_cast<size_t>(i));
    const double dx = std::cos(a), dy = std::sin(a);
    double best = HUGE_VAL;
    bool box = false;
    for (const Segment& g : w) {
      // sensor + t d = g1 + u (g2 - g1)
      const double ex = g.x2 - g.x1, ey = g.y2 - g.y1;
      const double den = dx * ey - dy * ex;
      if (std::abs(den) < 1e-12) continue;
      const double t = ((g.x1 - sensor.x) * ey - (g.y1 - sensor.y) * ex) / den;
      const double u = ((g.x1 - sensor.x) * dy - (g.y1 - sensor.y) * dx) / den;
      if (t > 0 && u >= 0 && u <= 1 && t < best) best = t, box = g.moving;
    }
    s.ranges.push_back(static_cast<float>(best + noise(rng)));
    s.valid.push_back(1);
    hits_box.push_back(box);
  }
  return s;
}

struct Drive {
  std::vector<io::LaserScan> scans;
  std::vector<common::Pose2> poses;
  std::vector<bool> box_point;  // per map point, in cloud order
  std::vector<io::PosedScan> posed() const {
    std::vector<io::PosedScan> out;
    for (size_t i = 0; i < scans.size(); ++i) out.push_back({poses[i], &scans[i]});
    return out;
  }
  size_t boxPoints() const { return static_cast<size_t>(std::count(box_point.begin(), box_point.end(), true)); }
};

// The box's and the walls' points a mask leaves out.
struct LeftOut {
  size_t box = 0, wall = 0;
};
LeftOut leftOut(const Drive& d, const io::PointMask& kept) {
  LeftOut n;
  for (size_t i = 0; i < d.box_point.size(); ++i) (d.box_point[i] ? n.box : n.wall) += kept.keeps(i) ? 0 : 1;
  return n;
}

// Along the room heading +x, then back heading -x (`laps` times); the box is there for the scans
// `box_at` says.
Drive drive(const std::function<bool(size_t)>& box_at, int laps = 1) {
  Drive d;
  std::mt19937 rng(7);
  for (int lap = 0; lap < laps; ++lap) {
    for (int k = 0; k <= 14; ++k) d.poses.push_back({-7.0 + k, -4, 0});
    for (int k = 0; k <= 14; ++k) d.poses.push_back({7.0 - k, 4, M_PI});
  }
  std::vector<bool> hits;
  for (size_t i = 0; i < d.poses.size(); ++i) {
    d.scans.push_back(castScan(d.poses[i], world(box_at(i)), rng, hits));
    for (size_t b = 0; b < hits.size(); ++b)
      if (d.scans.back().valid[b]) d.box_point.push_back(hits[b]);
  }
  return d;
}

}  // namespace

// The box the first three scans saw is gone for the later ones, which looked through its place:
// every one of its points is left out, and not one point of the walls.
TEST(MovingPoints, WhatLaterScansSawThroughIsLeftOutAndTheWallsStay) {
  const Drive d = drive([](size_t i) { return i < 3; });
  const auto posed = d.posed();
  ASSERT_EQ(d.box_point.size(), io::countMapPoints(posed));
  const size_t box_points = d.boxPoints();
  ASSERT_GT(box_points, 30u);
  const slam::MovingPointsResult r = slam::findMovingPoints(posed, {});
  ASSERT_EQ(r.static_points.size(), d.box_point.size());
  const LeftOut out = leftOut(d, r.static_points);
  EXPECT_EQ(out.box, box_points);
  EXPECT_EQ(out.wall, 0u);
  EXPECT_EQ(r.moving, box_points);
  // The cloud written with the mask holds the walls only.
  EXPECT_EQ(io::countMapPoints(posed, 1, &r.static_points), d.box_point.size() - box_points);
}

// The same in a longer drive, the box seen in its second half only: the keyframes are judged in
// runs on several threads, and the verdicts must land on their own points, in cloud order.
TEST(MovingPoints, AcrossRunsOfKeyframesTheVerdictsKeepTheirPoints) {
  const Drive d = drive([](size_t i) { return i >= 300 && i < 303; }, 12);  // 360 scans
  const size_t box_points = d.boxPoints();
  ASSERT_GT(box_points, 30u);
  const slam::MovingPointsResult r = slam::findMovingPoints(d.posed(), {});
  ASSERT_EQ(r.static_points.size(), d.box_point.size());
  const LeftOut out = leftOut(d, r.static_points);
  EXPECT_EQ(out.box, box_points);
  EXPECT_EQ(out.wall, 0u);
  EXPECT_EQ(r.moving, box_points);
}

// A box that stays is part of the world: nothing is left out.
TEST(MovingPoints, AStaticWorldLosesNoPoint) {
  const Drive d = drive([](size_t) { return true; });
  const slam::MovingPointsResult r = slam::findMovingPoints(d.posed(), {});
  EXPECT_EQ(r.moving, 0u);
  EXPECT_EQ(r.static_points.kept(), d.box_point.size());
}

// One scan that saw through is not enough with min_views = 2 (it may be misplaced): the box that
// one scan facing it missed is kept.
TEST(MovingPoints, OneWitnessIsNotEnough) {
  const Drive d = drive([](size_t i) { return i != 5; });
  slam::MovingPointsOptions o;
  EXPECT_EQ(slam::findMovingPoints(d.posed(), o).moving, 0u);
  o.min_views = 1;
  EXPECT_GT(slam::findMovingPoints(d.posed(), o).moving, 0u);
}
