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

// The exact test, as the definition writes it: d^2 with S = H Sigma H' + R, Sigma the exact joint
// covariance of (x_i, x_j) (which refactorises f) and H the error's Jacobians.
GateResult referenceGate(Esdf& f, int i, int j, const Vec3& z, const Mat3& omega, double probability) {
  Mat3 ai, aj;
  relativePoseErrorJacobians(f.mean(i), f.mean(j), z, &ai, &aj);
  Eigen::Matrix<double, 3, 6> h;
  h << ai, aj;
  const Eigen::MatrixXd s = h * f.jointCovariance(i, j) * h.transpose() + omega.inverse();
  return mahalanobisGate(-relativePoseError(f.mean(i), f.mean(j), z), s, probability);
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
    const GateResult ref = referenceGate(f, i, j, z, omega, 0.95);
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

// The same drive in every filter: metre steps turning left every 20 (information odo), the map
// factorised at pose 40, and a closure from pose 5 to pose closure_to of the dead-reckoned chain
// after it (information omega).
void squareDrive(const std::vector<Esdf*>& filters, int poses, int closure_to, const Mat3& odo, const Mat3& omega) {
  for (Esdf* f : filters) f->initialise(Vec3::Zero(), Mat3::Identity() * 1e-8);
  for (int k = 1; k < poses; ++k) {
    const Vec3 step(1.0, 0.0, (k % 20 == 0) ? M_PI / 2 : 0.0);
    for (Esdf* f : filters) f->augmentRelative(k - 1, step, odo);
    if (k == 40)
      for (Esdf* f : filters) f->recover();
    if (k == closure_to)
      for (Esdf* f : filters) f->observeRelative(5, closure_to, between(f->mean(5), f->mean(closure_to)), omega);
  }
}

TEST(Gating, ConservativeBoundDecidesOnlyWhatTheExactTestWouldDecideAlike) {
  // The conservative covariance bounds the exact one from above (the last factorisation holds
  // less information; dead reckoning and the newest closure's path add, never remove), so its
  // d^2 is never larger: gated with it, a closure is never refused that the exact test admits.
  // The exact mode refuses by that bound first and computes the exact covariance only for what
  // the bound admits: its decisions must be the exact test's. Three filters are fed the same
  // loop with a factorisation midway and a closure after it; one gates conservatively, one
  // exactly, and the reference's exact joint covariance (H Sigma H', which refactorises only
  // the reference) decides for comparison.
  std::mt19937 rng(42);
  EsdfOptions ex, co;
  ex.chi2_gate_probability = co.chi2_gate_probability = 0.95;
  ex.gate_covariance = CovarianceMode::Exact;
  co.gate_covariance = CovarianceMode::Conservative;
  Esdf fe(ex), fc(co), fr(ex);
  const Mat3 odo = Vec3(400.0, 400.0, 4000.0).asDiagonal();
  const Mat3 omega = Vec3(100.0, 100.0, 1000.0).asDiagonal();
  const std::vector<Esdf*> all{&fe, &fc, &fr};
  squareDrive(all, 81, 60, odo, omega);  // the closure for the conservative path through it
  int compared = 0, admitted_more = 0, refused_by_bound = 0, exact_accepted = 0, stale_rounds = 0;
  const long long factorisations_before = fe.factorisations();
  for (int t = 0; t < 300; ++t) {
    // A new pose every fifth closure leaves the factor stale again (an exact covariance
    // refactorises it).
    if (t % 5 == 0) {
      for (Esdf* f : all) f->augmentRelative(f->currentPose(), Vec3(1.0, 0.0, 0.0), odo);
      // ...and a closure into the old poses, so that the bound is looser than the exact value.
      for (Esdf* f : all) f->observeRelative(t % 40, f->currentPose(), between(f->mean(t % 40), f->mean(f->currentPose())), omega);
      stale_rounds += 1;
    }
    const int i = t % 40, j = 41 + (t * 7) % 39;
    const Vec3 z = between(fe.mean(i), fe.mean(j)) + Vec3(test::gauss(rng, 1.0), test::gauss(rng, 1.0), test::gauss(rng, 0.2));
    const GateResult e = fe.gateRelative(i, j, z, omega), c = fc.gateRelative(i, j, z, omega);
    ASSERT_EQ(e.covariance_used, c.covariance_used);
    if (!e.covariance_used) continue;
    ++compared;
    const GateResult ref = referenceGate(fr, i, j, z, omega, 0.95);
    EXPECT_LE(c.mahalanobis2, ref.mahalanobis2 * (1 + 1e-9)) << i << " " << j;
    if (ref.accepted) {
      EXPECT_TRUE(c.accepted) << i << " " << j;
    }
    admitted_more += c.accepted && !ref.accepted;
    EXPECT_EQ(e.accepted, ref.accepted) << i << " " << j;
    if (e.accepted) {
      EXPECT_NEAR(e.mahalanobis2, ref.mahalanobis2, 1e-9 * ref.mahalanobis2);
    }
    refused_by_bound += !e.accepted && e.mahalanobis2 < ref.mahalanobis2 * (1 - 1e-9);
    exact_accepted += ref.accepted;
  }
  EXPECT_GT(compared, 100);
  EXPECT_GT(exact_accepted, 10);
  EXPECT_GT(refused_by_bound, 10);
  // Refactorised only where the bound admitted a closure, not in every round that needed a
  // covariance (each round's first exact covariance refactorises; the rest reuse it).
  EXPECT_LT(fe.factorisations() - factorisations_before, stale_rounds / 2);
  RecordProperty("factorisations", static_cast<int>(fe.factorisations() - factorisations_before));
  // Not so loose that it admits everything the exact gate refuses.
  int refused_by_both = 0;
  for (int t = 0; t < 40; ++t) {
    const int i = t, j = 41 + t % 39;
    const Vec3 z = between(fe.mean(i), fe.mean(j)) + Vec3(8.0, -6.0, 1.0);
    refused_by_both += !fe.gateRelative(i, j, z, omega).accepted && !fc.gateRelative(i, j, z, omega).accepted;
  }
  EXPECT_EQ(refused_by_both, 40);
  RecordProperty("admitted_more", admitted_more);
  RecordProperty("refused_by_bound", refused_by_bound);
}

TEST(Gating, ARefusalWithoutFactorisingIsTheGatesOwnAndCostsNoFactorisation) {
  // A caller with costly checks left (the loop closer's shifted restarts) asks first whether
  // the gate will refuse a closure anyway. The answer comes from what needs no factorisation
  // (the bound from R alone, the conservative covariance, the exact one from the last
  // factorisation and the closures since); when it is a refusal, gateRelative refuses the same
  // closure with the same d^2, and when it is none, the closure may be admitted. A closure
  // after the factorisation makes the conservative covariance looser than the exact one, so
  // some refusals need the exact one.
  std::mt19937 rng(7);
  EsdfOptions o;
  o.chi2_gate_probability = 0.95;
  o.gate_covariance = CovarianceMode::Exact;
  EsdfOptions oc = o;
  oc.gate_covariance = CovarianceMode::Conservative;
  Esdf f(o), reference(o), conservative(oc);
  const Mat3 odo = Vec3(400.0, 400.0, 4000.0).asDiagonal();
  const Mat3 omega = Vec3(100.0, 100.0, 1000.0).asDiagonal();
  squareDrive({&f, &reference, &conservative}, 71, 55, odo, omega);
  int refused = 0, undecided = 0, refused_by_the_exact_covariance = 0;
  for (int t = 0; t < 200; ++t) {
    const int i = t % 40, j = 41 + (t * 7) % 29;
    const double spread = t % 2 == 0 ? 0.05 : 3.0;  // consistent closures and look-alike places
    const Vec3 z = between(f.mean(i), f.mean(j)) + Vec3(test::gauss(rng, spread), test::gauss(rng, spread), test::gauss(rng, 0.1 * spread));
    const long long before = f.factorisations();
    const std::optional<GateResult> early = f.refusalWithoutFactorising(i, j, z, omega);
    EXPECT_EQ(f.factorisations(), before);
    const GateResult full = reference.gateRelative(i, j, z, omega);
    if (early) {
      ++refused;
      EXPECT_FALSE(early->accepted);
      EXPECT_FALSE(full.accepted) << i << " " << j;
      EXPECT_NEAR(early->mahalanobis2, full.mahalanobis2, 1e-9 * full.mahalanobis2);
      refused_by_the_exact_covariance += conservative.gateRelative(i, j, z, omega).accepted;
    } else {
      ++undecided;
    }
  }
  // Every kind occurs: far-off measurements the bounds refuse, some only the exact covariance
  // refuses, and the rest.
  EXPECT_GT(refused, 20);
  EXPECT_GT(refused_by_the_exact_covariance, 0);
  EXPECT_GT(undecided, 20);
  RecordProperty("refused_by_the_exact_covariance", refused_by_the_exact_covariance);
}

// Two closures gated jointly: d^2 of the stacked innovations against the 6-dof quantile, with
// the covariance of both relative poses from the dense inverse of Lambda (the reference knows
// nothing of factors or path solves). A drift that puts each of two neighbouring closures just
// beyond the single gate passes when the two measure it alike, and fails when they disagree.
TEST(Gating, TwoClosuresThatAgreePassTheJointGateWhereEachAloneFails) {
  EsdfOptions o;
  o.chi2_gate_probability = 0.99;
  Esdf f(o);
  const Mat3 odo = Vec3(400.0, 400.0, 4000.0).asDiagonal(), omega = Vec3(400.0, 400.0, 4000.0).asDiagonal();
  squareDrive({&f}, 61, -1, odo, omega);
  // A closure since the factorisation at pose 40: the pair's covariance then comes from the
  // last factor and that closure (ExactUpdates.cpp), with no factorisation.
  f.observeRelative(10, 50, between(f.mean(10), f.mean(50)), omega);
  const long long factorisations = f.factorisations();
  const auto reference = [&](int i1, int j1, const Vec3& z1, int i2, int j2, const Vec3& z2) {
    const Eigen::MatrixXd sigma = Eigen::MatrixXd(f.state().denseInformation()).inverse();
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(6, sigma.cols());
    Eigen::VectorXd nu(6);
    Mat3 a, b;
    relativePoseErrorJacobians(f.mean(i1), f.mean(j1), z1, &a, &b);
    h.block<3, 3>(0, 3 * i1) += a, h.block<3, 3>(0, 3 * j1) += b;
    relativePoseErrorJacobians(f.mean(i2), f.mean(j2), z2, &a, &b);
    h.block<3, 3>(3, 3 * i2) += a, h.block<3, 3>(3, 3 * j2) += b;
    nu << -relativePoseError(f.mean(i1), f.mean(j1), z1), -relativePoseError(f.mean(i2), f.mean(j2), z2);
    Eigen::MatrixXd s = h * sigma * h.transpose();
    s.block<3, 3>(0, 0) += omega.inverse(), s.block<3, 3>(3, 3) += omega.inverse();
    return nu.dot(s.ldlt().solve(nu));
  };
  // Closures (5, 55) and (6, 56) of a drive that never came back: both say the second end lies
  // `shift` further along pose 5's heading than the estimate has it. d^2 of one grows as shift^2.
  const auto closures = [&](double shift1, double shift2) {
    const Vec3 z1 = between(f.mean(5), f.mean(55)), z2 = between(f.mean(6), f.mean(56));
    const Vec3 d1 = Vec3(std::cos(f.mean(5).z()), std::sin(f.mean(5).z()), 0);
    // The shift along pose 5's x as seen from each closure's earlier pose.
    const auto shifted = [&](int i, const Vec3& z, double shift) -> Vec3 {
      const Vec3 world = shift * d1;
      const double c = std::cos(f.mean(i).z()), s = std::sin(f.mean(i).z());
      return z + Vec3(c * world.x() + s * world.y(), -s * world.x() + c * world.y(), 0);
    };
    return std::make_pair(shifted(5, z1, shift1), shifted(6, z2, shift2));
  };
  const double unit = f.gateRelative(5, 55, closures(1.0, 1.0).first, omega).mahalanobis2;
  const double shift = std::sqrt(13.0 / unit);  // d^2 about 13: beyond 11.34 (3 dof), within 16.81 (6 dof)
  const auto [z1, z2] = closures(shift, shift);
  const GateResult one = f.gateRelative(5, 55, z1, omega), two = f.gateRelative(6, 56, z2, omega);
  EXPECT_FALSE(one.accepted) << one.mahalanobis2;
  EXPECT_FALSE(two.accepted) << two.mahalanobis2;
  const GateResult both = f.gateRelativePair(5, 55, z1, omega, 6, 56, z2, omega);
  EXPECT_NEAR(both.threshold, chi2Quantile(0.99, 6), 1e-9);
  EXPECT_NEAR(both.mahalanobis2, reference(5, 55, z1, 6, 56, z2), 1e-8 * both.mahalanobis2);
  EXPECT_GE(both.mahalanobis2, std::max(one.mahalanobis2, two.mahalanobis2) - 1e-9);  // a marginal is never larger
  EXPECT_TRUE(both.accepted) << both.mahalanobis2;
  EXPECT_EQ(f.factorisations(), factorisations);
  // The second closure measuring the opposite shift: each alone as far, jointly refused.
  const auto [w1, w2] = closures(shift, -shift);
  const GateResult apart = f.gateRelativePair(5, 55, w1, omega, 6, 56, w2, omega);
  EXPECT_NEAR(apart.mahalanobis2, reference(5, 55, w1, 6, 56, w2), 1e-8 * apart.mahalanobis2);
  EXPECT_FALSE(apart.accepted) << apart.mahalanobis2;
  // With a current factor: path solves of it, the same d^2.
  f.recover();
  const GateResult again = f.gateRelativePair(5, 55, z1, omega, 6, 56, z2, omega);
  EXPECT_GT(f.factorisations(), factorisations);
  EXPECT_NEAR(again.mahalanobis2, reference(5, 55, z1, 6, 56, z2), 1e-8 * again.mahalanobis2);
}

INSTANTIATE_TEST_SUITE_P(Modes, GatingLoop, ::testing::Values(CovarianceMode::Exact, CovarianceMode::Conservative));

}  // namespace
}  // namespace urbanslam::esdf
