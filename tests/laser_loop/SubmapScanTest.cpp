// The virtual 360° scan from recent scans (SubmapScan.h) against ray casting in a known room:
// every sector must hold the wall point the sensor would see from the current pose, the front
// and rear views of one place must fill the whole circle, and the window must drop old scans.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "urbanslam/laser_loop/SubmapScan.h"

using namespace urbanslam;
using namespace urbanslam::laser_loop;

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kHalfX = 4.0, kHalfY = 2.5;  // convex rectangular room centred on the origin

// Distance from (x, y) inside the room to its wall along the world bearing a.
double rayCast(double x, double y, double a) {
  const double c = std::cos(a), s = std::sin(a);
  double t = 1e9;
  if (std::fabs(c) > 1e-12) t = std::min(t, ((c > 0 ? kHalfX : -kHalfX) - x) / c);
  if (std::fabs(s) > 1e-12) t = std::min(t, ((s > 0 ? kHalfY : -kHalfY) - y) / s);
  return t;
}

// A 180° laser (1° beams, mounted facing forward) at vehicle pose p.
io::LaserScan frontScan(const common::Pose2& p) {
  io::LaserScan s;
  s.angle_min_rad = -90 * kDeg;
  s.angle_increment_rad = kDeg;
  s.max_range_m = 80;
  for (int i = 0; i <= 180; ++i) {
    s.ranges.push_back(static_cast<float>(rayCast(p.x, p.y, p.phi + s.bearing(static_cast<size_t>(i)))));
    s.valid.push_back(1);
  }
  return s;
}

// Each valid sector's range lies within the ray-cast ranges across that sector (sampled finely).
void expectConsistentWithRoom(const PolarScan& v, const common::Pose2& at) {
  for (size_t k = 0; k < v.ranges.size(); ++k) {
    if (!v.valid[k]) continue;
    double lo = 1e9, hi = 0;
    for (int j = -10; j <= 10; ++j) {
      const double r = rayCast(at.x, at.y, at.phi + v.bearings[k] + 0.05 * j * v.angle_increment_rad);
      lo = std::min(lo, r);
      hi = std::max(hi, r);
    }
    EXPECT_GE(v.ranges[k], lo - 1e-4) << "sector " << k;
    EXPECT_LE(v.ranges[k], hi + 1e-4) << "sector " << k;
  }
}

}  // namespace

TEST(SubmapScan, FrontAndRearViewsOfOnePlaceFillTheCircle) {
  SubmapScanBuilder b(5.0, 1.0, 50.0);
  const common::Pose2 forward{1.0, -0.5, 0.3}, turned{1.0, -0.5, 0.3 + M_PI};
  b.add(forward, {frontScan(forward)});
  const PolarScan v = b.add(turned, {frontScan(turned)});
  ASSERT_EQ(v.ranges.size(), 360u);
  EXPECT_TRUE(v.closed);
  EXPECT_EQ(std::count(v.valid.begin(), v.valid.end(), 1), 360);
  expectConsistentWithRoom(v, turned);
}

TEST(SubmapScan, PastScansAreMovedIntoTheCurrentFrame) {
  SubmapScanBuilder b(3.0, 1.0, 50.0);
  const common::Pose2 earlier{-2.0, 0.2, 0.1}, now{0.0, 0.0, 0.4};
  b.add(earlier, {frontScan(earlier)});
  const PolarScan v = b.add(now, {frontScan(now)});
  EXPECT_EQ(b.scansInWindow(), 2u);
  // The earlier scan saw walls behind the current pose: more than the current 180° are filled.
  EXPECT_GT(std::count(v.valid.begin(), v.valid.end(), 1), 200);
  expectConsistentWithRoom(v, now);
}

TEST(SubmapScan, ScansOlderThanTheWindowAreDropped) {
  SubmapScanBuilder b(1.0, 1.0, 50.0);
  const common::Pose2 earlier{-2.0, 0.0, 0.0}, now{0.0, 0.0, 0.0};
  b.add(earlier, {frontScan(earlier)});
  const PolarScan v = b.add(now, {frontScan(now)});
  EXPECT_EQ(b.scansInWindow(), 1u);
  // Only the current forward half (bearings −90°..90°) is seen.
  for (size_t k = 0; k < v.ranges.size(); ++k) {
    if (std::fabs(v.bearings[k]) > 91 * kDeg) {
      EXPECT_FALSE(v.valid[k]) << "sector " << k;
    }
  }
  expectConsistentWithRoom(v, now);
}
