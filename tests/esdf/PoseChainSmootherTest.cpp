// The Rauch-Tung-Striebel pose-chain smoother against the batch optimum of the same least-squares
// problem (the pose-graph back end, iterated to convergence) and against the truth.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <random>

#include "TestUtil.h"
#include "urbanslam/esdf/PoseChainSmoother.h"
#include "urbanslam/esdf/PoseGraphBackend.h"

namespace urbanslam::esdf {
namespace {

using test::gauss;

struct Chain {
  std::vector<Vec3> truth;
  std::vector<Vec3> motions;                   // motions[i]: from pose i-1 to pose i (motions[0] unused)
  std::vector<std::pair<size_t, Vec3>> fixes;  // measured world poses
};

const Mat3 kMotionCov = Eigen::Vector3d(0.02 * 0.02, 0.02 * 0.02, std::pow(0.5 * M_PI / 180, 2)).asDiagonal();
const Mat3 kFixCov = Eigen::Vector3d(0.1 * 0.1, 0.1 * 0.1, std::pow(2.0 * M_PI / 180, 2)).asDiagonal();

// A drive that turns one way, then the other, a fix every `fix_every` poses from `first_fix` on.
Chain makeChain(std::mt19937& rng, size_t n, size_t first_fix, size_t fix_every) {
  Chain c;
  c.truth.push_back({3, -2, 0.4});
  c.motions.push_back(Vec3::Zero());
  for (size_t i = 1; i < n; ++i) {
    const Vec3 u(0.5, 0.0, (i < n / 2 ? 1 : -1) * 0.08);
    c.truth.push_back(compose(c.truth.back(), u));
    c.motions.push_back(u + Vec3(gauss(rng, 0.02), gauss(rng, 0.02), gauss(rng, 0.5 * M_PI / 180)));
  }
  for (size_t i = first_fix; i < n; i += fix_every)
    c.fixes.push_back({i, c.truth[i] + Vec3(gauss(rng, 0.1), gauss(rng, 0.1), gauss(rng, 2.0 * M_PI / 180))});
  return c;
}

PoseChainSmoother smootherOf(const Chain& c) {
  PoseChainSmoother s;
  size_t f = 0;
  for (size_t i = 0; i < c.motions.size(); ++i) {
    s.addPose(toPose(c.motions[i]), kMotionCov);
    for (; f < c.fixes.size() && c.fixes[f].first == i; ++f) s.addFix(toPose(c.fixes[f].second), kFixCov);
  }
  return s;
}

// The same problem as a pose graph: vertex 0 the world origin (anchored), vertex i + 1 pose i. A
// fix is an edge from the origin, e = ⊖z ⊕ x = R(z)' (x - z) in position: its information is the
// fix's turned into z's frame, so that both costs are the same function of the poses.
std::vector<Vec3> batchOptimum(const Chain& c) {
  PoseGraph g;
  g.vertices.push_back({0, Vec3::Zero()});
  for (size_t i = 0; i < c.truth.size(); ++i) g.vertices.push_back({static_cast<long>(i + 1), Vec3::Zero()});
  const Mat3 motion_info = kMotionCov.inverse();
  const auto fixEdge = [&](size_t i, const Vec3& z) {
    Mat3 r = Mat3::Identity();
    r.topLeftCorner<2, 2>() << std::cos(z.z()), -std::sin(z.z()), std::sin(z.z()), std::cos(z.z());
    g.edges.push_back({0, static_cast<long>(i + 1), z, r.transpose() * kFixCov.inverse() * r});
  };
  // The first pose hangs from the origin by the first fix carried back along the chain, with no
  // weight to speak of (it only orders the vertices for the back end); the fixes do the rest.
  Vec3 start = c.fixes.front().second;
  for (size_t i = c.fixes.front().first; i > 0; --i) start = compose(start, inverse(c.motions[i]));
  g.edges.push_back({0, 1, start, Mat3::Identity() * 1e-9});
  size_t f = 0;
  for (size_t i = 0; i < c.truth.size(); ++i) {
    if (i > 0) g.edges.push_back({static_cast<long>(i), static_cast<long>(i + 1), c.motions[i], motion_info});
    for (; f < c.fixes.size() && c.fixes[f].first == i; ++f) fixEdge(i, c.fixes[f].second);
  }
  PoseGraphBackendOptions o;
  o.filter.relinearise_cost_tolerance = 1e-12;
  o.anchor_sigma_m = 1e-9;  // the origin does not move
  o.anchor_sigma_rad = 1e-10;
  const PoseGraphBackendResult r = runPoseGraphBackend(g, o);
  return {r.poses.begin() + 1, r.poses.end()};
}

double positionError(const common::Pose2& a, const Vec3& b) { return std::hypot(a.x - b.x(), a.y - b.y()); }

TEST(PoseChainSmoother, AgreesWithTheBatchOptimumOfTheSameProblem) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    const Chain c = makeChain(rng, 80, 0, 7);
    const PoseChainSmoother s = smootherOf(c);
    const std::vector<common::Pose2> smoothed = s.smooth();
    const std::vector<Vec3> batch = batchOptimum(c);
    ASSERT_EQ(smoothed.size(), batch.size());
    double worst = 0, moved = 0, worst_phi = 0, moved_phi = 0;
    // The forward filter alone, for scale: how far the backward pass moves the poses.
    PoseChainSmoother forward;
    size_t f = 0;
    for (size_t i = 0; i < c.motions.size(); ++i) {
      forward.addPose(toPose(c.motions[i]), kMotionCov);
      for (; f < c.fixes.size() && c.fixes[f].first == i; ++f) forward.addFix(toPose(c.fixes[f].second), kFixCov);
      moved = std::max(moved, positionError(forward.filtered(), batch[i]));
      moved_phi = std::max(moved_phi, std::abs(common::wrapToPi(forward.filtered().phi - batch[i].z())));
    }
    for (size_t i = 0; i < batch.size(); ++i) {
      worst = std::max(worst, positionError(smoothed[i], batch[i]));
      worst_phi = std::max(worst_phi, std::abs(common::wrapToPi(smoothed[i].phi - batch[i].z())));
    }
    // The iterated passes reach the optimum, while the filter is decimetres from it.
    EXPECT_LT(worst, 1e-5) << "trial " << trial;
    EXPECT_LT(worst_phi, 5e-6) << "trial " << trial;
    EXPECT_GT(moved, 0.05) << "trial " << trial;
    // One pass (the plain RTS smoother) is already within millimetres: linearised where the
    // filter was, it differs from the optimum in second order only.
    const std::vector<common::Pose2> once = s.smooth(1);
    double once_worst = 0;
    for (size_t i = 0; i < batch.size(); ++i) once_worst = std::max(once_worst, positionError(once[i], batch[i]));
    EXPECT_LT(once_worst, 0.01) << "trial " << trial;
    EXPECT_GT(once_worst, 10 * worst) << "trial " << trial;
  }
}

TEST(PoseChainSmoother, SmoothedPosesAreCloserToTheTruthThanFilteredOnes) {
  std::mt19937 rng(11);
  double smoothed_sum = 0, filtered_sum = 0;
  size_t count = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const Chain c = makeChain(rng, 60, 0, 5);
    PoseChainSmoother s;
    size_t f = 0;
    for (size_t i = 0; i < c.motions.size(); ++i) {
      s.addPose(toPose(c.motions[i]), kMotionCov);
      for (; f < c.fixes.size() && c.fixes[f].first == i; ++f) s.addFix(toPose(c.fixes[f].second), kFixCov);
      filtered_sum += positionError(s.filtered(), c.truth[i]);
    }
    const std::vector<common::Pose2> smoothed = s.smooth();
    for (size_t i = 0; i < smoothed.size(); ++i) smoothed_sum += positionError(smoothed[i], c.truth[i]);
    count += smoothed.size();
  }
  EXPECT_LT(smoothed_sum / count, 0.75 * filtered_sum / count);
}

TEST(PoseChainSmoother, PosesBeforeTheFirstFixFollowTheChainBackFromIt) {
  std::mt19937 rng(3);
  const Chain c = makeChain(rng, 40, 15, 5);
  const PoseChainSmoother s = smootherOf(c);
  const std::vector<common::Pose2> smoothed = s.smooth();
  ASSERT_EQ(smoothed.size(), 40u);
  for (size_t i = 0; i < 15; ++i) {
    const Vec3 back = compose(toVec(smoothed[i + 1]), inverse(c.motions[i + 1]));
    EXPECT_NEAR(smoothed[i].x, back.x(), 1e-9);
    EXPECT_NEAR(smoothed[i].y, back.y(), 1e-9);
    EXPECT_NEAR(common::wrapToPi(smoothed[i].phi - back.z()), 0.0, 1e-9);
  }
  // ... and agree with the batch optimum there too (the chain floats until the first fix).
  const std::vector<Vec3> batch = batchOptimum(c);
  for (size_t i = 0; i < 40; ++i) EXPECT_LT(positionError(smoothed[i], batch[i]), 3e-3) << "pose " << i;
}

TEST(PoseChainSmoother, NothingToSmoothWithoutAFix) {
  PoseChainSmoother s;
  s.addPose({}, kMotionCov);
  s.addPose({1, 0, 0}, kMotionCov);
  EXPECT_FALSE(s.hasFix());
  EXPECT_TRUE(s.smooth().empty());
  EXPECT_THROW(s.filtered(), std::logic_error);
}

}  // namespace
}  // namespace urbanslam::esdf
