#include <gtest/gtest.h>

#include <cmath>

#include "urbanslam/sim/OdometrySimulator.h"

namespace urbanslam::sim {
namespace {

// An hour of fixes at 1 Hz with no noise: a fix is either on the true position or shifted by
// exactly multipath_jump_m, and the shifted share is what a renewal process of events of rate p
// lasting d gives, p d / (1 + p d); outages remove fixes in the same proportion.
TEST(GpsSimulator, MultipathJumpsAndOutagesFollowTheirRates) {
  GpsOptions o;
  o.enabled = true;
  o.sigma_m = 0;
  o.outage_probability = 0;
  o.multipath_probability = 0.01;
  o.multipath_duration_s = 10;
  o.multipath_jump_m = 15;
  GpsSimulator gps(o, 5);
  size_t fixes = 0, jumped = 0;
  for (int k = 1; k <= 3600 * 20; ++k) {
    VehicleState s;
    s.time_s = k;
    s.pose = {0.5 * k, 0.0, 0.0};
    io::GpsFix f;
    ASSERT_TRUE(gps.read(s, k, f));
    ++fixes;
    const double d = std::hypot(f.x_m - s.pose.x, f.y_m - s.pose.y);
    if (d > 1e-9) {
      EXPECT_NEAR(d, 15.0, 1e-9);
      ++jumped;
    }
  }
  const double share = static_cast<double>(jumped) / static_cast<double>(fixes), expected = 0.1 / 1.1;
  EXPECT_NEAR(share, expected, 0.02);

  o.multipath_probability = 0;
  o.outage_probability = 0.01;
  o.outage_min_s = o.outage_max_s = 10;
  GpsSimulator lossy(o, 6);
  size_t lost = 0;
  const int n = 3600 * 20;
  for (int k = 1; k <= n; ++k) {
    VehicleState s;
    s.time_s = k;
    io::GpsFix f;
    lost += lossy.read(s, k, f) ? 0 : 1;
  }
  EXPECT_NEAR(static_cast<double>(lost) / n, expected, 0.02);
}

}  // namespace
}  // namespace urbanslam::sim
