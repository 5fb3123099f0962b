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

namespace urbanslam::slam {
namespace {

// A drive of 20,000 odometry readings, a keyframe at every tenth, each keyframe placed where the
// odometry puts it in a map frame turned and shifted against the odometry's: the trajectory at
// every reading is then that reading moved into the map frame, whichever of its readings and
// edges have gone to the spill files (4,096 a chunk) and after a save and a load.
TEST(Map, ALongDrivesSpilledReadingsAndEdgesComeBackWhole) {
  const common::Pose2 map_from_odom{12.0, -3.0, 0.7};
  const auto odomAt = [](size_t i) {
    const double t = 0.1 * static_cast<double>(i);
    return common::Pose2{20 * std::sin(0.05 * t), 0.5 * t, common::wrapToPi(0.3 * std::cos(0.02 * t))};
  };
  constexpr size_t kReadings = 20000;
  Map map(nullptr, 4.0);
  std::vector<GraphEdge> edges;
  for (size_t i = 0; i < kReadings; ++i) {
    const double t = 0.1 * static_cast<double>(i);
    map.addOdometry(t, odomAt(i));
    if (i % 10 != 0) continue;
    const size_t k = map.size();
    map.addKeyframe({k, t, common::compose(map_from_odom, odomAt(i)), false, false, {}}, {});
    map.addAnchor({t, k, {}, odomAt(i)});  // the reading at the scan's time hangs from it
    if (k > 0) {
      GraphEdge e{k - 1, k, common::between(odomAt(i - 10), odomAt(i)), Eigen::Matrix3d::Identity() * static_cast<double>(k), false};
      map.addEdge(e);
      edges.push_back(e);
    }
  }
  const auto expectDrive = [&](const Map& m) {
    const auto traj = m.odometryTrajectory();
    ASSERT_EQ(traj.size(), kReadings);
    for (size_t i = 0; i < kReadings; ++i) {
      const common::Pose2 want = common::compose(map_from_odom, odomAt(i));
      ASSERT_NEAR(traj[i].timestamp, 0.1 * static_cast<double>(i), 1e-9) << i;
      ASSERT_NEAR(traj[i].pose.x, want.x, 1e-9) << i;
      ASSERT_NEAR(traj[i].pose.y, want.y, 1e-9) << i;
      ASSERT_NEAR(common::wrapToPi(traj[i].pose.phi - want.phi), 0.0, 1e-9) << i;
    }
    const auto got = m.edges().toVector();
    ASSERT_EQ(got.size(), edges.size());
    for (size_t j = 0; j < edges.size(); ++j) {
      ASSERT_EQ(got[j].from, edges[j].from) << j;
      ASSERT_EQ(got[j].to, edges[j].to) << j;
      ASSERT_EQ(got[j].measurement.x, edges[j].measurement.x) << j;
      ASSERT_EQ(got[j].information(2, 2), edges[j].information(2, 2)) << j;
    }
  };
  expectDrive(map);

  common::BinaryWriter w;
  map.writeState(w);
  Map loaded(nullptr, 4.0);
  common::BinaryReader r(w.bytes().data(), w.bytes().size(), "map state");
  loaded.readState(r);
  r.expectEnd();
  expectDrive(loaded);
}

}  // namespace
}  // namespace urbanslam::slam
