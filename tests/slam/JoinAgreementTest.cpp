// A merged session's closures before the join's fixes are in must put its keyframes where one of
// the join's fixes does (agreesWithJoin), with the tolerance two fixes must agree within; refused
// ones go on record with reason Join (GlobalSlam::setJoinCheck). Hand-computed poses.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include <Eigen/Dense>

#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/slam/GlobalSlam.h"
#include "urbanslam/slam/Map.h"
#include "urbanslam/slam/SessionJoin.h"

using namespace urbanslam;

TEST(JoinAgreement, AClosureMustPutTheKeyframeWhereAFixOfTheJoinDoesWithinTheDriftSinceIt) {
  // Two agreeing fixes, at the session's keyframes 0 and 2 (path 0 and 200 m), whose transforms
  // differ by 2 m along the map's y (agreeing within 1 m + 2 % of 200 m). agree_m 1, agree_per_m
  // 0.02, agree_deg 5 (SessionJoinOptions).
  slam::SessionJoin join;
  join.fixes.resize(2);
  join.fixes[0].keyframe = 0;
  join.fixes[0].transform = {10, 5, M_PI / 2};
  join.fixes[1].keyframe = 2;
  join.fixes[1].transform = {10, 7, M_PI / 2};
  join.agreeing = {0, 1};
  const std::vector<double> path_m{0, 100, 200};
  const common::Pose2 pose{3, 0, 0};  // keyframe 1 in the session's frame: (10, 8) or (10, 10), heading 90°, in the map's
  EXPECT_TRUE(slam::agreesWithJoin(join, 1, pose, path_m, {10.0, 8.0, M_PI / 2}));   // where fix 0 puts it
  EXPECT_TRUE(slam::agreesWithJoin(join, 1, pose, path_m, {10.0, 10.0, M_PI / 2}));  // where fix 1 does
  EXPECT_TRUE(slam::agreesWithJoin(join, 1, pose, path_m, {10.0, 12.9, M_PI / 2}));  // 2.9 m from fix 1, 100 m of path: 3 m allowed
  EXPECT_FALSE(slam::agreesWithJoin(join, 1, pose, path_m, {10.0, 13.1, M_PI / 2}));
  EXPECT_FALSE(slam::agreesWithJoin(join, 2, pose, path_m, {10.0, 13.5, M_PI / 2}));  // at fix 1's keyframe: 1 m from it, 5 m from fix 0
  EXPECT_TRUE(slam::agreesWithJoin(join, 2, pose, path_m, {10.0, 10.9, M_PI / 2}));
  EXPECT_FALSE(slam::agreesWithJoin(join, 1, pose, path_m, {10.0, 8.0 + 103, M_PI / 2}));             // a look-alike place 103 m along
  EXPECT_FALSE(slam::agreesWithJoin(join, 1, pose, path_m, {10.0, 8.0, M_PI / 2 + 6 * M_PI / 180}));  // turned by 6°
  join.options.agree_deg = 10;
  EXPECT_TRUE(slam::agreesWithJoin(join, 1, pose, path_m, {10.0, 8.0, M_PI / 2 + 6 * M_PI / 180}));
  join.agreeing = {0};  // only the first fix
  EXPECT_FALSE(slam::agreesWithJoin(join, 1, pose, path_m, {10.0, 10.0 + 2.5, M_PI / 2}));
}

// Keyframes 0..205 a metre apart along x, each step 1 m uncertain (sigma): keyframe 200 is 7 m
// uncertain relative to keyframe 150, as a session hanging loosely from a map. Two agreeing
// closures from 150 and 151 measure it `measured_m` ahead; the check refuses any that is not
// within 1 m of 50 m.
std::vector<slam::LoopClosureRecord> closuresWithCheck(double measured_m, bool check) {
  slam::PipelineOptions options;
  options.loop_closure.appearance_min_sigma_m = 100;  // the camera's full pose is taken however uncertain the estimate
  slam::PipelineStats stats;
  std::vector<slam::PipelineObserver*> observers;
  slam::Map map{std::make_unique<esdf::Esdf>(), 2.0};
  slam::GlobalSlam global(options, map, stats, observers);
  slam::KeyframeConstraint c;
  c.z = {1.0, 0, 0};
  c.cov = Eigen::Vector3d(1.0, 1.0, 1e-6).asDiagonal();
  for (size_t k = 0; k <= 205; ++k) global.addKeyframe({k, static_cast<double>(k), {}, false, true, {}}, io::CompactScan(), c);
  if (check) global.setJoinCheck([](const slam::LoopClosureRecord& r) { return std::abs(r.measurement.x - 50.0) > 1.0; });
  for (size_t earlier : {size_t{150}, size_t{151}}) {
    slam::CameraMeasurement m;
    m.mount = common::Pose2{0.0, 0.0, 0.0};
    m.relative.valid = true;
    m.relative.cov = Eigen::Vector2d(1e-4, 1e-4).asDiagonal();
    m.relative.depth_per_baseline = 0.5;
    m.metric.valid = true;
    m.metric.pose = common::Pose2{measured_m, 0.0, 0.0};
    m.metric.cov = Eigen::Vector3d(1e-4, 1e-4, 1e-6).asDiagonal();
    global.proposeImageClosure(earlier, earlier + 50, 1.0, m, std::chrono::steady_clock::now());
  }
  global.finish();
  return global.closures();
}

TEST(JoinAgreement, GlobalSlamRefusesTheClosuresTheJoinCheckSaysContradictTheJoin) {
  // 10 m off: inside the filter's gate (d^2 = 100 / 50 = 2), so without the check the look-alike
  // place goes in.
  const auto unchecked = closuresWithCheck(60.0, false);
  EXPECT_TRUE(std::any_of(unchecked.begin(), unchecked.end(), [](const slam::LoopClosureRecord& c) { return c.accepted; }));
  const auto refused = closuresWithCheck(60.0, true);
  ASSERT_EQ(refused.size(), 2u);
  for (const auto& c : refused) {
    EXPECT_FALSE(c.accepted);
    EXPECT_EQ(c.reason, slam::ClosureReason::Join);
    EXPECT_STREQ(slam::reasonName(c.reason), "join");
  }
  const auto agreeing = closuresWithCheck(50.3, true);
  ASSERT_EQ(agreeing.size(), 2u);
  for (const auto& c : agreeing) EXPECT_TRUE(c.accepted);
}
