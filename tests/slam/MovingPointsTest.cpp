#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include "CastScan.h"
#include "urbanslam/io/MapOutputs.h"
#include "urbanslam/slam/MovingPoints.h"

using namespace urbanslam;

namespace {

using test::Segment;

// A room 20 m x 16 m, and a 1 m box that stands in it for the first scans only (or always).
std::vector<Segment> world(bool with_box) {
  std::vector<Segment> w = {{-10, -8, 10, -8, false}, {10, -8, 10, 8, false}, {10, 8, -10, 8, false}, {-10, 8, -10, -8, false}};
  if (with_box) test::addBox(w, 3, -0.5, 4, 0.5, true);
  return w;
}

// The scans: from a sensor 0.5 m ahead of the vehicle, 40 m range (the room's walls are nearer).
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
    d.scans.push_back(test::castScan(d.poses[i], world(box_at(i)), 0.5, 40, rng, &hits));
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
