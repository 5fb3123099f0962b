// Chi-square quantiles and the innovation gate on consistent and inconsistent loop closures.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "TestUtil.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/Gating.h"

namespace urbanslam::esdf {
namespace {

TEST(Gating, Chi2QuantilesMatchTables) {
  // Standard table values.
  EXPECT_NEAR(chi2Quantile(0.95, 1), 3.841458821, 1e-8);
  EXPECT_NEAR(chi2Quantile(0.95, 2), 5.991464547, 1e-8);
  EXPECT_NEAR(chi2Quantile(0.95, 3), 7.814727903, 1e-8);
  EXPECT_NEAR(chi2Quantile(0.99, 3), 11.34486673, 1e-7);
  EXPECT_NEAR(chi2Quantile(0.999, 3), 16.26623620, 1e-7);
  EXPECT_NEAR(chi2Quantile(0.5, 10), 9.341817766, 1e-8);
  // Closed form for 2 dof: -2 ln(1 - p).
  EXPECT_NEAR(chi2Quantile(0.9, 2), -2 * std::log(0.1), 1e-9);
}

class GatingLoop : public ::testing::TestWithParam<CovarianceMode> {};

TEST_P(GatingLoop, AcceptsConsistentRejectsInconsistentClosure) {
  EsdfOptions o;
  o.chi2_gate_probability = 0.99;
  o.gate_covariance = GetParam();
  Esdf f(o);
  std::mt19937 rng(40);
  const Mat3 odo = Vec3(400.0, 400.0, 4000.0).asDiagonal();
  // A 10 m square driven once: the true pose 40 coincides with pose 0.
  std::vector<Vec3> truth{Vec3::Zero()};
  f.initialise(Vec3::Zero(), Mat3::Identity() * 1e-8);
  for (int k = 1; k <= 40; ++k) {
    const Vec3 step(1.0, 0.0, (k % 10 == 0) ? M_PI / 2 : 0.0);
    truth.push_back(compose(truth.back(), step));
    f.augmentRelative(k - 1, step + Vec3(test::gauss(rng, 0.05), test::gauss(rng, 0.05), test::gauss(rng, 0.016)), odo);
    if (k == 20) f.recover();  // a factor for the conservative mode to start from
  }
  const Mat3 loop = Vec3(100.0, 100.0, 1000.0).asDiagonal();
  const Vec3 z_true = between(truth[0], truth[40]);
  // Inconsistent: the place recognised 5 m away (a false match) is rejected, Lambda untouched.
  const auto before = f.state().denseInformation();
  const ObservationResult bad = f.observeRelative(0, 40, z_true + Vec3(5.0, -3.0, 0.8), loop, true);
  EXPECT_FALSE(bad.accepted);
  EXPECT_GT(bad.gate.mahalanobis2, bad.gate.threshold);
  EXPECT_EQ((f.state().denseInformation() - before).norm(), 0.0);
  // Consistent: the true relative pose plus measurement noise is accepted.
  const ObservationResult good = f.observeRelative(0, 40, z_true + Vec3(0.05, -0.05, 0.01), loop, true);
  EXPECT_TRUE(good.accepted) << good.gate.mahalanobis2 << " vs " << good.gate.threshold;
  EXPECT_NEAR(good.gate.threshold, chi2Quantile(0.99, 3), 1e-9);
}

TEST(Gating, BoundShortcutNeverAcceptsWhatTheFullTestRejects) {
  // d^2 = e' (H Sigma H' + R)^-1 e <= e' Omega e: the shortcut is conservative in the right
  // direction. Check it against the full test on random closures of a drifting loop.
  std::mt19937 rng(41);
  EsdfOptions o;
  o.chi2_gate_probability = 0.95;
  Esdf f(o);
  f.initialise(Vec3::Zero(), Mat3::Identity() * 1e-8);
  for (int k = 1; k <= 60; ++k)
    f.augmentRelative(k - 1, Vec3(1.0, 0.0, (k % 15 == 0) ? M_PI / 2 : 0.0), Vec3(400.0, 400.0, 4000.0).asDiagonal());
  const Mat3 omega = Vec3(100.0, 100.0, 1000.0).asDiagonal();
  int shortcut = 0, full = 0;
  for (int t = 0; t < 200; ++t) {
    const int i = t % 30, j = 30 + t % 30;
    const Vec3 z = between(f.mean(i), f.mean(j)) + Vec3(test::gauss(rng, 0.3), test::gauss(rng, 0.3), test::gauss(rng, 0.1));
    const GateResult g = f.gateRelative(i, j, z, omega);
    Mat3 ai, aj;
    relativePoseErrorJacobians(f.mean(i), f.mean(j), z, &ai, &aj);
    Eigen::Matrix<double, 3, 6> h;
    h << ai, aj;
    const Eigen::MatrixXd s = h * f.jointCovariance(i, j) * h.transpose() + omega.inverse();
    const GateResult ref = mahalanobisGate(-relativePoseError(f.mean(i), f.mean(j), z), s, 0.95);
    EXPECT_EQ(g.accepted, ref.accepted);
    if (!g.covariance_used) {
      EXPECT_LE(ref.mahalanobis2, g.mahalanobis2 + 1e-12);
      ++shortcut;
    } else {
      EXPECT_NEAR(g.mahalanobis2, ref.mahalanobis2, 1e-9 * ref.mahalanobis2);
      ++full;
    }
  }
  EXPECT_GT(shortcut, 0);
  EXPECT_GT(full, 0);
}

INSTANTIATE_TEST_SUITE_P(Modes, GatingLoop, ::testing::Values(CovarianceMode::Exact, CovarianceMode::Conservative));

}  // namespace
}  // namespace urbanslam::esdf
