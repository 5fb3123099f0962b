// Exact covariances between factorisations (a Woodbury update of the last factor by the
// closures since) against the dense inverse of the current information matrix, with the
// factorisations counted to show which path answered.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <utility>
#include <vector>

#include "TestUtil.h"
#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::esdf {
namespace {

const Mat3 kOdoInfo = Vec3(100.0, 100.0, 1000.0).asDiagonal();
const Mat3 kLoopInfo = Vec3(400.0, 400.0, 4000.0).asDiagonal();

// No relinearisation: the information form stays the linear system the dense inverse solves.
EsdfOptions linearOptions() {
  EsdfOptions o;
  o.relinearise = false;
  return o;
}

// A drive around blocks: `poses` poses with noisy odometry, then a full recovery (the factor).
void drive(Esdf& f, std::mt19937& rng, int poses) {
  f.initialise(Vec3::Zero(), Mat3::Identity() * 1e-6);
  for (int k = 1; k < poses; ++k) {
    const double turn = (k % 10 == 0) ? M_PI / 2 : 0.0;
    f.augmentRelative(k - 1, Vec3(1.0 + test::gauss(rng, 0.05), test::gauss(rng, 0.05), turn + test::gauss(rng, 0.01)), kOdoInfo);
  }
}

void extend(Esdf& f, int poses) {
  for (int k = 0; k < poses; ++k) f.augmentRelative(f.size() - 1, Vec3(1, 0, 0.05), kOdoInfo);
}

// A closure measuring the current relative pose with an offset (so that it adds information).
void close(Esdf& f, int i, int j) { f.observeRelative(i, j, between(f.mean(i), f.mean(j)) + Vec3(0.05, -0.03, 0.01), kLoopInfo); }

Mat6 denseJoint(const Esdf& f, int i, int j) {
  const Eigen::MatrixXd sigma = f.state().denseInformation().inverse();
  Mat6 s;
  s << sigma.block<3, 3>(3 * i, 3 * i), sigma.block<3, 3>(3 * i, 3 * j), sigma.block<3, 3>(3 * j, 3 * i), sigma.block<3, 3>(3 * j, 3 * j);
  return s;
}

double relativeDifference(const Mat6& a, const Mat6& b) { return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff(); }

TEST(ExactUpdates, ClosuresSinceTheFactorAreAppliedWithoutRefactorising) {
  std::mt19937 rng(41);
  Esdf f(linearOptions());
  drive(f, rng, 60);
  f.recover();  // the factor: 60 poses
  const long long factored = f.factorisations();
  // Driving on past the factor, closing into the factored map, within the chain, between two
  // factored poses and at the newest pose twice (a confirmed pair).
  extend(f, 12);
  close(f, 8, 70);
  extend(f, 5);
  close(f, 20, 40);
  close(f, 64, 76);
  close(f, 9, 76);
  const std::vector<std::pair<int, int>> pairs{{9, 76}, {8, 70}, {30, 76}, {64, 71}, {76, 76}, {40, 40}};
  for (auto [i, j] : pairs) {
    const Mat6 exact = f.jointCovariance(i, j, CovarianceMode::Exact);
    EXPECT_LT(relativeDifference(exact, denseJoint(f, i, j)), 1e-8) << i << " " << j;
  }
  EXPECT_EQ(f.factorisations(), factored) << "every pair was answered from the old factor";
  // The gate decides on that covariance too: a consistent closure passes, an inconsistent one not.
  const Vec3 z = between(f.mean(12), f.mean(76));
  EXPECT_TRUE(f.gateRelative(12, 76, z + Vec3(0.3, 0, 0), kLoopInfo).accepted);
  EXPECT_FALSE(f.gateRelative(12, 76, z + Vec3(8, 0, 0), kLoopInfo).accepted);
  EXPECT_EQ(f.factorisations(), factored);
}

TEST(ExactUpdates, ManyNewPosesToSolveForRefactoriseInstead) {
  // Closures onto a few factored poses not solved for yet are answered by their path solves;
  // onto more than four by refactorising.
  for (const int closures : {3, 5}) {
    std::mt19937 rng(42);
    Esdf f(linearOptions());
    drive(f, rng, 60);
    f.recover();
    const long long factored = f.factorisations();
    extend(f, 4);
    for (int c = 0; c < closures; ++c) close(f, 1 + c * 50 / closures, f.size() - 1);
    const int last = f.size() - 1;
    EXPECT_LT(relativeDifference(f.jointCovariance(1, last, CovarianceMode::Exact), denseJoint(f, 1, last)), 1e-8) << closures;
    EXPECT_EQ(f.factorisations(), factored + (closures > 3 ? 1 : 0)) << closures;
  }
}

TEST(ExactUpdates, ARelinearisationSinceTheFactorRefactorises) {
  std::mt19937 rng(43);
  Esdf f;  // relinearising
  drive(f, rng, 40);
  f.recover();
  extend(f, 3);
  f.observeRelative(2, 42, between(f.mean(2), f.mean(42)) + Vec3(2.0, 1.0, 0.3), kLoopInfo, false);
  // Move the poses far enough that relinearising changes the factors' contributions.
  f.recoverRecent(0);
  ASSERT_GT(f.relineariseMoved(), 0);
  const long long before = f.factorisations();
  const Mat6 exact = f.jointCovariance(2, 42, CovarianceMode::Exact);
  EXPECT_EQ(f.factorisations(), before + 1);
  EXPECT_LT(relativeDifference(exact, denseJoint(f, 2, 42)), 1e-8);
}

TEST(ExactUpdates, AFilterReadBackAnswersAsTheOneWritten) {
  std::mt19937 rng(44);
  Esdf f(linearOptions());
  drive(f, rng, 50);
  f.recover();
  extend(f, 6);
  close(f, 5, 55);
  f.augmentRelative(20, Vec3(0.5, 0.2, 0.1), kOdoInfo);  // a lineage of the chain from pose 20
  extend(f, 2);
  common::BinaryWriter w;
  f.writeState(w);
  Esdf g(linearOptions());
  common::BinaryReader r(w.bytes().data(), w.bytes().size(), "filter state");
  g.readState(r);
  r.expectEnd();
  for (Esdf* e : {&f, &g}) {
    const long long before = e->factorisations();
    const Mat6 exact = e->jointCovariance(7, 55, CovarianceMode::Exact);
    EXPECT_EQ(e->factorisations(), before);
    EXPECT_LT(relativeDifference(exact, denseJoint(f, 7, 55)), 1e-8);
  }
  EXPECT_EQ(f.jointCovariance(7, 55, CovarianceMode::Exact), g.jointCovariance(7, 55, CovarianceMode::Exact));
  EXPECT_EQ(f.jointCovariance(58, 53, CovarianceMode::Conservative), g.jointCovariance(58, 53, CovarianceMode::Conservative));
  // A state from before the record (format 8) refactorises at its first exact covariance.
  common::BinaryReader old(w.bytes().data(), w.bytes().size() - 9, "filter state");
  Esdf h(linearOptions());
  h.readState(old, false);
  old.expectEnd();
  h.jointCovariance(7, 55, CovarianceMode::Exact);
  EXPECT_EQ(h.factorisations(), 1);
}

}  // namespace
}  // namespace urbanslam::esdf
