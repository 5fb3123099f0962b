// The space a scan's beams passed through (BeamFreeSpace), against the world the scan was
// ray-cast in: whether a point is seen through is decided independently by casting rays from the
// sensor to it in the world.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "SyntheticScan.h"
#include "urbanslam/alignment/BeamFreeSpace.h"
#include "urbanslam/alignment/ScanModel.h"
#include "urbanslam/alignment/SeenThroughRate.h"

namespace urbanslam::alignment {
namespace {

// The distance from `from` to the first wall along the direction of `to`; infinity: none.
double wallDistance(const test::World& w, const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
  const Eigen::Vector2d d = (to - from).normalized();
  const io::LaserScan one = test::simulateScan(w, {from.x(), from.y(), std::atan2(d.y(), d.x())}, {2, 1e-9, 1e3, 0.0, 1});
  return one.valid[0] ? static_cast<double>(one.ranges[0]) : HUGE_VAL;
}

// The shortest and longest wall distance over directions within `spread` of the one to `to`:
// whether a point is seen through or hidden must not hinge on where the beams happen to fall.
std::pair<double, double> wallRange(const test::World& w, const Eigen::Vector2d& from, const Eigen::Vector2d& to, double spread) {
  double lo = HUGE_VAL, hi = 0;
  const double a = std::atan2(to.y() - from.y(), to.x() - from.x());
  for (int k = -4; k <= 4; ++k) {
    const double b = a + spread * k / 4;
    const double d = wallDistance(w, from, from + Eigen::Vector2d(std::cos(b), std::sin(b)));
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  return {lo, hi};
}

double distanceToWalls(const test::World& w, const Eigen::Vector2d& p) {
  double best = HUGE_VAL;
  for (const auto& s : w) {
    const Eigen::Vector2d e = s.b - s.a;
    const double t = std::clamp((p - s.a).dot(e) / e.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (s.a + t * e - p).norm());
  }
  return best;
}

test::ScanSpec fullTurn() {
  test::ScanSpec spec;
  spec.beams = 720;
  spec.fov_rad = 2 * M_PI * 719 / 720;
  return spec;
}

TEST(BeamFreeSpace, CountsThePointsTheBeamsPassedThrough) {
  // A scan taken by a sensor mounted off the vehicle's centre, its points in the vehicle frame.
  const test::World world = test::roomWorld();
  const common::Pose2 vehicle{1.0, -0.5, 0.4}, mount{0.3, 0.1, 0.2};
  const common::Pose2 sensor = common::compose(vehicle, mount);
  io::LaserScan scan = test::simulateScan(world, sensor, fullTurn());
  scan.sensor_pose = mount;
  const BeamFreeSpace beams(pointSetFromScan(scan, ScanModelOptions{}, true), 0.3, 0.05);
  ASSERT_TRUE(beams.valid());
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> ux(-12, 12), uy(-8, 8);
  std::vector<Eigen::Vector2d> in_front, hidden;
  const Eigen::Vector2d origin(sensor.x, sensor.y);
  while (in_front.size() < 300 || hidden.size() < 300) {
    const Eigen::Vector2d p(ux(rng), uy(rng));
    if (distanceToWalls(world, p) < 0.3 || (p - origin).norm() < 0.3) continue;
    const auto [near, far] = wallRange(world, origin, p, 1.5 * M_PI / 180);
    const double r = (p - origin).norm();
    if (r < 0.8 * (near - 0.3 - 0.05 * near) && in_front.size() < 300) in_front.push_back(p);
    if (r > far + 0.3 && hidden.size() < 300) hidden.push_back(p);
  }
  // Every point the world says the beams passed is counted, none behind a wall (the points are
  // in the world frame, where the scan sits at the vehicle pose).
  EXPECT_EQ(beams.conflicts(in_front, vehicle), 300);
  EXPECT_EQ(beams.conflicts(hidden, vehicle), 0);
}

TEST(SeenThroughRate, StartsAtItsPriorLearnsAndForgets) {
  SeenThroughRate rate(0.05, 200, 10000);
  EXPECT_DOUBLE_EQ(rate.rate(), 0.05);
  rate.add(800, 8);  // (10 + 8) / (200 + 800)
  EXPECT_DOUBLE_EQ(rate.rate(), 18.0 / 1000.0);
  rate.add(0, 0);  // nothing in view says nothing
  EXPECT_DOUBLE_EQ(rate.rate(), 18.0 / 1000.0);
  // Outdoors: a long run at 30 % takes over; the indoor counts fade out.
  for (int k = 0; k < 200; ++k) rate.add(500, 150);
  EXPECT_NEAR(rate.rate(), 0.3, 0.01);
}

}  // namespace
}  // namespace urbanslam::alignment
