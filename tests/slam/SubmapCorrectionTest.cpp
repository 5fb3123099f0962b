// Local SLAM takes global SLAM's estimate of its submap at a fixed lag: the keyframes up to the
// estimate's newest take its geometry relative to that keyframe, which itself and the keyframes
// after it stay where local SLAM's chain put them.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "ConstantScan.h"
#include "urbanslam/slam/LocalSlam.h"
#include "urbanslam/slam/SubmapCorrections.h"

using namespace urbanslam;

namespace {

// Poses as homogeneous matrices: a reference independent of common::compose.
Eigen::Matrix3d mat(const common::Pose2& p) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  m.topLeftCorner<2, 2>() = Eigen::Rotation2Dd(p.phi).toRotationMatrix();
  m(0, 2) = p.x;
  m(1, 2) = p.y;
  return m;
}

io::LaserScan someScan(double t) { return test::constantScan(t, 5.0f, 30); }

void expectSame(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b, const std::string& what) {
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-9) << what << "\n" << a << "\n" << b;
}

}  // namespace

TEST(SubmapCorrection, KeyframesUpToTheEstimateTakeItsGeometryAnchoredAtItsNewest) {
  slam::PipelineOptions o;  // a submap of 5 keyframes
  slam::LocalSlam local(o);
  const common::Pose2 z{1.0, 0.0, 0.1};
  for (int i = 0; i < 7; ++i) local.keyframeAdded(someScan(i), z);  // keyframes 0..6; the submap holds 2..6
  const std::vector<common::Pose2> before = local.submapPoses();
  ASSERT_EQ(before.size(), 5u);

  // Global SLAM's view after keyframe 5 (keyframes 1..5), bent by closures and in its own frame.
  slam::SubmapEstimate e{5, {}};
  for (int i = 1; i <= 5; ++i) e.poses.push_back({10.0 + 1.1 * i, 5.0 + 0.2 * i * i, 1.0 + 0.05 * i});
  local.correctSubmap(e);
  const std::vector<common::Pose2> after = local.submapPoses();
  ASSERT_EQ(after.size(), 5u);

  // Keyframe 5 (the anchor) and 6 (after it) are unchanged; 2..4 sit where the estimate puts
  // them relative to keyframe 5.
  expectSame(mat(after[3]), mat(before[3]), "keyframe 5");
  expectSame(mat(after[4]), mat(before[4]), "keyframe 6");
  for (int k = 2; k <= 4; ++k) {
    const Eigen::Matrix3d expected = mat(before[3]) * mat(e.poses[4]).inverse() * mat(e.poses[static_cast<size_t>(k - 1)]);
    expectSame(mat(after[static_cast<size_t>(k - 2)]), expected, "keyframe " + std::to_string(k));
    // and not where they were
    EXPECT_GT((mat(after[static_cast<size_t>(k - 2)]) - mat(before[static_cast<size_t>(k - 2)])).cwiseAbs().maxCoeff(), 0.01);
  }
}

TEST(SubmapCorrection, AnEstimateWhoseNewestKeyframeLeftTheSubmapChangesNothing) {
  slam::PipelineOptions o;
  slam::LocalSlam local(o);
  for (int i = 0; i < 8; ++i) local.keyframeAdded(someScan(i), {0.5, 0.1, -0.05});  // the submap holds 3..7
  const auto before = local.submapPoses();
  local.correctSubmap({2, {{0, 0, 0}, {3, 3, 3}, {7, 1, 2}}});
  const auto after = local.submapPoses();
  for (size_t i = 0; i < before.size(); ++i) expectSame(mat(after[i]), mat(before[i]), "keyframe " + std::to_string(i + 3));
}

TEST(SubmapCorrections, TakeGivesTheEstimateOfThatKeyframeAndDropsOlderOnes) {
  slam::SubmapCorrections c;
  for (size_t k = 0; k < 4; ++k) c.publish({k, {{static_cast<double>(k), 0, 0}}});
  EXPECT_FALSE(c.take(7).has_value());  // not published (yet): and the others are gone now
  EXPECT_FALSE(c.take(3).has_value());
  for (size_t k = 4; k < 6; ++k) c.publish({k, {{static_cast<double>(k), 0, 0}}});
  const auto e = c.take(5);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->keyframe, 5u);
  EXPECT_EQ(e->poses.at(0).x, 5.0);
  EXPECT_FALSE(c.take(4).has_value());  // older than one taken
}
