// A merged session's closures before the join's fixes are in must put its keyframes where one of
// the join's fixes does (agreesWithJoin), with the tolerance two fixes must agree within.
// Hand-computed poses. (Global SLAM refusing what the check says: GlobalSlamTest.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

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

TEST(JoinAgreement, APlaceSearchsFixEntersTheMapNoTighterThanTheJoinsAgreement) {
  // The join checked a place search's fix to agree_m (1 m) and agree_deg (5°), whatever the
  // search's posterior says (2 cm here; 3 m along x for one in a corridor). A classifier's
  // detection was aligned: its covariance is the alignment's.
  const slam::SessionJoinOptions options;
  slam::SessionFix place;
  place.detector = slam::Proposer::Place;
  place.cov = Eigen::Vector3d(4e-4, 4e-4, 1e-6).asDiagonal();
  const Eigen::Matrix3d c = slam::fixCovariance(place, options);
  EXPECT_DOUBLE_EQ(c(0, 0), 1.0);
  EXPECT_DOUBLE_EQ(c(1, 1), 1.0);
  EXPECT_NEAR(std::sqrt(c(2, 2)) * 180 / M_PI, 5.0, 1e-12);
  place.cov(0, 0) = 9.0;
  EXPECT_DOUBLE_EQ(slam::fixCovariance(place, options)(0, 0), 9.0);
  slam::SessionFix laser = place;
  laser.detector = slam::Proposer::Laser;
  laser.cov = Eigen::Vector3d(4e-4, 4e-4, 1e-6).asDiagonal();
  EXPECT_TRUE(slam::fixCovariance(laser, options).isApprox(laser.cov));
}
