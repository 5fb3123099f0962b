// Local SLAM's matcher learning how far its odometry's heading really errs: the first search
// narrows to what the corrections need, and a turn beyond that (which the odometry model's own
// window holds) is still found, by the search of the full window that a doubtful match starts.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "../alignment/SyntheticScan.h"
#include "urbanslam/slam/LocalSubmap.h"

using namespace urbanslam;
namespace at = urbanslam::alignment::test;

namespace {

io::LaserScan roomScan(const common::Pose2& pose, unsigned seed) {
  at::ScanSpec spec;
  spec.seed = seed;
  return at::simulateScan(at::roomWorld(), pose, spec);
}

TEST(LocalSubmap, AHeadingErrorBeyondTheLearntWindowIsStillFound) {
  const slam::LocalOptions o;  // a 5° window at least
  slam::LocalSubmap submap(o);
  submap.addKeyframe(roomScan({0, 0, 0}, 1));
  const std::vector<common::Pose2> poses{common::Pose2{}};
  // The model's heading sigma is 0.1 rad (17° of window each side); this odometry errs by a
  // few milliradians.
  const Eigen::Matrix3d cov = Eigen::Vector3d(0.025 * 0.025, 0.025 * 0.025, 0.01).asDiagonal();
  std::mt19937 rng(3);
  std::normal_distribution<double> heading_error(0, 0.005);
  alignment::PriorMatchResult last;
  for (unsigned k = 0; k < 60; ++k) {
    const common::Pose2 truth{0.3, 0.05, 0.02};
    const common::Pose2 odometry{truth.x, truth.y, truth.phi + heading_error(rng)};
    last = submap.match(roomScan(truth, 10 + k), odometry, cov, poses);
    ASSERT_TRUE(last.valid) << k << ": " << last.failure_reason;
    EXPECT_NEAR(last.pose.phi, truth.phi, 0.005) << k;
  }
  // The search has narrowed to the configured floor.
  EXPECT_NEAR(last.search_half_angle_rad, o.search_window_deg * M_PI / 180, 1e-12);
  // Odometry that missed 11° of turning: outside that window, inside the model's.
  const common::Pose2 truth{0.3, 0.05, 0.22}, odometry{0.3, 0.05, 0.02};
  const alignment::PriorMatchResult r = submap.match(roomScan(truth, 99), odometry, cov, poses);
  ASSERT_TRUE(r.valid) << r.failure_reason;
  EXPECT_NEAR(r.pose.phi, truth.phi, 0.005);
  EXPECT_NEAR(r.pose.x, truth.x, 0.02);
  EXPECT_NEAR(r.pose.y, truth.y, 0.02);
  EXPECT_NEAR(r.search_half_angle_rad, 3 * 0.1, 1e-12);  // the full window found it
}

}  // namespace
