#include <gtest/gtest.h>

#include <cmath>

#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/slam/Map.h"

namespace urbanslam::slam {
namespace {

// Two keyframes 2 m apart along x, a scan matched 1 m after the first one but 0.1 m to its
// left, and odometry readings that go straight: the trajectory passes through every anchored
// scan at its time, and between anchors it moves with the odometry, its drift spread by time.
TEST(Map, TrajectoryPassesThroughAnchoredScansAndBlendsBetweenThem) {
  Map map(nullptr, 4.0);
  map.addOdometry(0.0, {0, 0, 0});
  map.addKeyframe({0, 0.0, {0, 0, 0}, false, false, {}}, {});
  map.addAnchor({0.0, 0, {}, {0, 0, 0}});
  map.addOdometry(0.5, {0.5, 0, 0});
  map.addOdometry(1.0, {1.0, 0, 0});
  map.addAnchor({1.0, 0, {1.0, 0.1, 0}, {1.0, 0, 0}});  // the scan at t = 1 matched 0.1 m left of the odometry
  map.addOdometry(1.5, {1.5, 0, 0});
  map.addOdometry(2.0, {2.0, 0, 0});
  map.addKeyframe({1, 2.0, {2.0, 0, 0}, false, false, {}}, {});
  map.addAnchor({2.0, 1, {}, {2.0, 0, 0}});

  const auto scans = map.scanTrajectory();
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_NEAR(scans[1].pose.y, 0.1, 1e-12);
  const auto traj = map.odometryTrajectory();
  const auto at = [&](double t) {
    for (const auto& p : traj)
      if (std::abs(p.timestamp - t) < 1e-9) return p.pose;
    ADD_FAILURE() << "no pose at " << t;
    return common::Pose2{};
  };
  EXPECT_NEAR(at(1.0).y, 0.1, 1e-12);  // at the scan's time: the scan's pose
  EXPECT_NEAR(at(2.0).y, 0.0, 1e-12);
  // Halfway between the scan (y 0.1) and the keyframe (y 0): forwards from the scan gives 0.1,
  // backwards from the keyframe 0, blended half and half.
  EXPECT_NEAR(at(1.5).x, 1.5, 1e-12);
  EXPECT_NEAR(at(1.5).y, 0.05, 1e-12);
  EXPECT_NEAR(at(0.5).y, 0.05, 1e-12);
}

TEST(Map, IndexFollowsThePosesAfterReindexing) {
  Map map(nullptr, 1.0);
  map.addKeyframe({0, 0.0, {0, 0, 0}, false, false, {}}, {});
  map.addKeyframe({1, 1.0, {10, 0, 0}, false, false, {}}, {});
  std::vector<size_t> near;
  map.index().query(10, 0, 0.5, near);
  ASSERT_EQ(near.size(), 1u);
  EXPECT_EQ(near[0], 1u);
  map.keyframe(1).pose = {0.2, 0, 0};  // a correction moved it
  map.reindex();
  near.clear();
  map.index().query(0, 0, 0.5, near);
  EXPECT_EQ(near.size(), 2u);
}

}  // namespace
}  // namespace urbanslam::slam
