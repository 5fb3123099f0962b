// Thesis eqs. 2.5-2.9: covariance <-> information relationships of the delayed state, checked on
// random SPD covariances against a dense inverse.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "urbanslam/esdf/CovarianceInformation.h"
#include "urbanslam/esdf/Esdf.h"

namespace {

TEST(InformationIdentities, BlockInverseEqs2_7to2_9) {
  std::mt19937 rng(20);
  std::normal_distribution<double> g(0, 1);
  for (int t = 0; t < 20; ++t) {
    const int nt = 3 * (1 + t % 4), nv = 3, n = nt + nv;
    Eigen::MatrixXd a(n, n);
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) a(r, c) = g(rng);
    const Eigen::MatrixXd p = a * a.transpose() + 0.5 * Eigen::MatrixXd::Identity(n, n);
    Eigen::VectorXd x(n);
    for (int k = 0; k < n; ++k) x(k) = g(rng);

    const Eigen::MatrixXd lambda = p.inverse();  // eq. 2.6
    const Eigen::VectorXd b = lambda * x;        // eq. 2.5
    const Eigen::MatrixXd ptt = p.topLeftCorner(nt, nt), ptv = p.topRightCorner(nt, nv);
    const Eigen::MatrixXd pvt = p.bottomLeftCorner(nv, nt), pvv = p.bottomRightCorner(nv, nv);
    const Eigen::MatrixXd ptt_inv = ptt.inverse();
    const Eigen::MatrixXd delta = pvv - pvt * ptt_inv * ptv;  // eq. 2.8
    const Eigen::MatrixXd di = delta.inverse();
    // eq. 2.7
    EXPECT_LT((lambda.topLeftCorner(nt, nt) - (ptt_inv + ptt_inv * ptv * di * pvt * ptt_inv)).norm(), 1e-8);
    EXPECT_LT((lambda.topRightCorner(nt, nv) - (-ptt_inv * ptv * di)).norm(), 1e-8);
    EXPECT_LT((lambda.bottomLeftCorner(nv, nt) - (-di * pvt * ptt_inv)).norm(), 1e-8);
    EXPECT_LT((lambda.bottomRightCorner(nv, nv) - di).norm(), 1e-8);
    // eq. 2.9, top and bottom blocks as written in the thesis.
    const Eigen::VectorXd xt = x.head(nt), xv = x.tail(nv);
    const Eigen::VectorXd bt = ptt_inv * (xt + ptv * di * pvt * ptt_inv * xt - ptv * di * xv);
    const Eigen::VectorXd bv = di * (-pvt * ptt_inv * xt + xv);
    EXPECT_LT((b.head(nt) - bt).norm(), 1e-8);
    EXPECT_LT((b.tail(nv) - bv).norm(), 1e-8);
  }
}

TEST(InformationIdentities, LibraryBlockFormulasEqualDenseInverse) {
  std::mt19937 rng(21);
  std::normal_distribution<double> g(0, 1);
  for (int nt : {0, 3, 9}) {
    const int n = nt + 3;
    Eigen::MatrixXd a(n, n);
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) a(r, c) = g(rng);
    const Eigen::MatrixXd p = a * a.transpose() + Eigen::MatrixXd::Identity(n, n);
    Eigen::VectorXd x(n);
    for (int k = 0; k < n; ++k) x(k) = g(rng);
    const auto info = urbanslam::esdf::informationFromCovariance(p, x, 3);
    EXPECT_LT((info.lambda - p.inverse()).norm(), 1e-9);
    EXPECT_LT((info.eta - p.inverse() * x).norm(), 1e-9);
  }
}

TEST(InformationIdentities, FilterStateSatisfiesThemAfterRecovery) {
  // The ESDF's own state: covariance from inverting Lambda, then eqs. 2.7-2.9 give Lambda, eta back.
  using namespace urbanslam::esdf;
  Esdf f;
  f.initialise(Vec3(1, 2, 0.3), Mat3::Identity() * 0.01);
  for (int k = 1; k < 8; ++k) f.augmentRelative(k - 1, Vec3(1, 0.1, 0.2), Vec3(100.0, 100.0, 1000.0).asDiagonal());
  f.observeRelative(0, 7, between(f.mean(0), f.mean(7)) + Vec3(0.1, 0, 0.02), Vec3(50.0, 50.0, 500.0).asDiagonal());
  f.recover();
  const Eigen::MatrixXd lambda = f.state().denseInformation();
  const auto info = informationFromCovariance(lambda.inverse(), f.state().denseMean(), 3);
  EXPECT_LT((info.lambda - lambda).norm() / lambda.norm(), 1e-9);
  EXPECT_LT((info.eta - f.state().denseEta()).norm() / f.state().denseEta().norm(), 1e-9);
}

}  // namespace
