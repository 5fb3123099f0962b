// Local SLAM's matcher learning how far its odometry's heading really errs: the first search
// narrows to what the corrections need, and a turn beyond that (which the odometry model's own
// window holds) is still found, by the search of the full window that a doubtful match starts.
// And learning that its odometry holds: matches then search the odometry's 3σ only, and odometry
// wrong in direction is still found by the wider search a doubtful match starts.
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

// A submap of one keyframe of the room at the origin, and the odometry model's covariance: 2.5 cm,
// and a heading sigma of 0.1 rad (17° of window each side).
class LocalSubmapInARoom : public ::testing::Test {
 protected:
  LocalSubmapInARoom() { submap.addKeyframe(roomScan({0, 0, 0}, 1)); }
  const slam::LocalOptions o;  // a 5° window at least
  slam::LocalSubmap submap{o};
  const std::vector<common::Pose2> poses{common::Pose2{}};
  const Eigen::Matrix3d cov = Eigen::Vector3d(0.025 * 0.025, 0.025 * 0.025, 0.01).asDiagonal();
};

TEST_F(LocalSubmapInARoom, AHeadingErrorBeyondTheLearntWindowIsStillFound) {
  // This odometry errs in heading by a few milliradians.
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

TEST_F(LocalSubmapInARoom, TrustedOdometryNarrowsTheSearchAndAReversalIsStillFound) {
  std::mt19937 rng(4);
  std::normal_distribution<double> error(0, 0.01);
  const common::Pose2 truth{0.3, 0.05, 0.02};
  int wide_late = 0;
  for (unsigned k = 0; k < 150; ++k) {
    const common::Pose2 odometry{truth.x + error(rng), truth.y + error(rng), truth.phi + 0.3 * error(rng)};
    const alignment::PriorMatchResult r = submap.match(roomScan(truth, 10 + k), odometry, cov, poses);
    ASSERT_TRUE(r.valid) << k << ": " << r.failure_reason;
    EXPECT_NEAR(r.pose.x, truth.x, 0.02) << k;
    EXPECT_NEAR(r.pose.y, truth.y, 0.02) << k;
    EXPECT_NEAR(r.pose.phi, truth.phi, 0.005) << k;
    if (k < 50) EXPECT_GT(r.search_half_width_m, 0.55) << k;  // distrusted at first: twice the travel wide
    if (k >= 100) wide_late += r.search_half_width_m > 0.5;
  }
  EXPECT_LE(wide_late, 5);  // trusted: the search keeps to the odometry's 3σ (the configured 0.3 m at least)
  // Reversing 0.55 m while the odometry reports going on: beyond the odometry's 3σ window, inside
  // the window of twice the travel that a doubtful match widens to.
  const common::Pose2 reversed{-0.25, 0.05, 0.02};
  const alignment::PriorMatchResult r = submap.match(roomScan(reversed, 200), truth, cov, poses);
  ASSERT_TRUE(r.valid) << r.failure_reason;
  EXPECT_NEAR(r.pose.x, reversed.x, 0.02);
  EXPECT_NEAR(r.pose.y, reversed.y, 0.02);
  EXPECT_NEAR(r.pose.phi, reversed.phi, 0.005);
  EXPECT_GE(r.search_half_width_m, 0.55);
}

}  // namespace
