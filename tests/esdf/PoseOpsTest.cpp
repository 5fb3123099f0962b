// Analytic vs numerical Jacobians of the compounding operators (thesis appendix B).
#include <gtest/gtest.h>

#include "TestUtil.h"
#include "urbanslam/common/Pose2.h"
#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::esdf {
namespace {

using test::numericalJacobian;
using V = Eigen::VectorXd;

TEST(PoseOps, ComposeInverseBetweenAgreeWithCommonPose2) {
  std::mt19937 rng(1);
  for (int t = 0; t < 100; ++t) {
    const Vec3 a = test::randomPose(rng), b = test::randomPose(rng);
    const auto pa = toPose(a), pb = toPose(b);
    const auto c = common::compose(pa, pb);
    const Vec3 c2 = compose(a, b);
    EXPECT_NEAR(c.x, c2.x(), 1e-12);
    EXPECT_NEAR(c.y, c2.y(), 1e-12);
    EXPECT_NEAR(c.phi, common::wrapToPi(c2.z()), 1e-12);
    const auto bt = common::between(pa, pb);
    const Vec3 bt2 = between(a, b);
    EXPECT_NEAR(bt.x, bt2.x(), 1e-12);
    EXPECT_NEAR(bt.y, bt2.y(), 1e-12);
    EXPECT_NEAR(bt.phi, bt2.z(), 1e-12);
    // ⊖a ⊕ a = 0 and a ⊕ (⊖a ⊕ b) = b.
    EXPECT_LT(compose(inverse(a), a).head<2>().norm(), 1e-12);
    EXPECT_LT(poseDifference(compose(a, between(a, b)), b).norm(), 1e-12);
  }
}

TEST(PoseOps, ComposeJacobiansMatchNumerical) {
  std::mt19937 rng(2);
  for (int t = 0; t < 50; ++t) {
    const Vec3 a = test::randomPose(rng), b = test::randomPose(rng);
    Mat3 j1, j2;
    composeJacobians(a, b, &j1, &j2);
    const Eigen::MatrixXd n1 = numericalJacobian([&](const V& x) -> V { return compose(x, b); }, a);
    const Eigen::MatrixXd n2 = numericalJacobian([&](const V& x) -> V { return compose(a, x); }, b);
    EXPECT_LT((j1 - n1).norm(), 1e-6);
    EXPECT_LT((j2 - n2).norm(), 1e-6);
  }
}

TEST(PoseOps, InverseJacobianMatchesNumerical) {
  std::mt19937 rng(3);
  for (int t = 0; t < 50; ++t) {
    const Vec3 a = test::randomPose(rng);
    const Eigen::MatrixXd n = numericalJacobian([&](const V& x) -> V { return inverse(x); }, a);
    EXPECT_LT((inverseJacobian(a) - n).norm(), 1e-6);
  }
}

TEST(PoseOps, BetweenJacobiansMatchNumericalAndCompositeRule) {
  std::mt19937 rng(4);
  for (int t = 0; t < 50; ++t) {
    const Vec3 a = test::randomPose(rng), b = test::randomPose(rng);
    Mat3 ja, jb;
    betweenJacobians(a, b, &ja, &jb);
    // Keep the numerical derivative away from the heading wrap.
    auto f = [&](const V& x, bool first) -> V {
      Vec3 r = first ? between(x, b) : between(a, x);
      r.z() = (first ? b.z() - x(2) : x(2) - a.z());
      return r;
    };
    EXPECT_LT((ja - numericalJacobian([&](const V& x) { return f(x, true); }, a)).norm(), 1e-6);
    EXPECT_LT((jb - numericalJacobian([&](const V& x) { return f(x, false); }, b)).norm(), 1e-6);
    // Appendix B.3: d(⊖a⊕b)/da = J1⊕(⊖a, b) J⊖(a), d/db = J2⊕(⊖a, b).
    Mat3 j1, j2;
    composeJacobians(inverse(a), b, &j1, &j2);
    EXPECT_LT((ja - j1 * inverseJacobian(a)).norm(), 1e-12);
    EXPECT_LT((jb - j2).norm(), 1e-12);
  }
}

TEST(PoseOps, BetweenCovarianceIsTheJointMappedByTheNumericalJacobian) {
  std::mt19937 rng(6);
  std::normal_distribution<double> g(0, 1);
  for (int t = 0; t < 20; ++t) {
    const Vec3 a = test::randomPose(rng), b = test::randomPose(rng);
    Eigen::Matrix<double, 6, 6> l;
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) l(r, c) = g(rng);
    const Eigen::Matrix<double, 6, 6> joint = l * l.transpose();
    V ab(6);
    ab << a, b;
    // Away from the heading wrap, as above.
    const Eigen::MatrixXd j = numericalJacobian(
        [&](const V& x) -> V {
          Vec3 r = between(x.head<3>(), x.tail<3>());
          r.z() = x(5) - x(2);
          return r;
        },
        ab);
    const Mat3 ref = j * joint * j.transpose();
    EXPECT_LT((betweenCovariance(a, b, joint) - ref).norm(), 1e-5 * ref.norm());
  }
}

TEST(PoseOps, RelativePoseErrorJacobiansMatchNumerical) {
  std::mt19937 rng(5);
  for (int t = 0; t < 50; ++t) {
    const Vec3 a = test::randomPose(rng), b = test::randomPose(rng);
    // A measurement near the truth keeps the error heading far from +-pi.
    Vec3 z = between(a, b) + Vec3(0.1, -0.2, 0.05);
    Mat3 ja, jb;
    relativePoseErrorJacobians(a, b, z, &ja, &jb);
    const auto na = numericalJacobian([&](const V& x) -> V { return relativePoseError(x, b, z); }, a);
    const auto nb = numericalJacobian([&](const V& x) -> V { return relativePoseError(a, x, z); }, b);
    EXPECT_LT((ja - na).norm(), 1e-6);
    EXPECT_LT((jb - nb).norm(), 1e-6);
    EXPECT_LT(relativePoseError(a, b, between(a, b)).norm(), 1e-12);
  }
}

TEST(PoseOps, RelativePoseErrorClosedFormEqualsTheCompositeChain) {
  // The closed form (two sin/cos pairs) against ⊖z ⊕ (⊖a ⊕ b) chained through the appendix-B
  // operators, at any headings (unwrapped ones too), and its Jacobians against the chain rule.
  std::mt19937 rng(6);
  for (int t = 0; t < 200; ++t) {
    const Vec3 a = test::randomPose(rng) + Vec3(0, 0, 4 * M_PI * (t % 3 - 1));
    const Vec3 b = test::randomPose(rng), z = test::randomPose(rng);
    Vec3 chain = compose(inverse(z), between(a, b));
    chain.z() = common::wrapToPi(chain.z());
    Mat3 ja, jb, j2, ha, hb;
    const Vec3 e = relativePoseError(a, b, z, &ja, &jb);
    EXPECT_LT((e - chain).norm(), 1e-12);
    composeJacobians(inverse(z), between(a, b), nullptr, &j2);
    betweenJacobians(a, b, &ha, &hb);
    EXPECT_LT((ja - j2 * ha).norm(), 1e-12);
    EXPECT_LT((jb - j2 * hb).norm(), 1e-12);
  }
}

TEST(PoseOps, DiagonalFloorsRaiseOnlyTheDiagonalEntriesBelowThem) {
  Mat3 cov;
  cov << 4e-4, 1e-4, 2e-5,  //
      1e-4, 9.0, 3e-5,      //
      2e-5, 3e-5, 1e-6;
  const Mat3 f = withDiagonalFloors(cov, 0.1, 0.01);
  EXPECT_DOUBLE_EQ(f(0, 0), 0.01);  // 2 cm raised to 10 cm
  EXPECT_DOUBLE_EQ(f(1, 1), 9.0);   // 3 m left as it is
  EXPECT_DOUBLE_EQ(f(2, 2), 1e-4);  // 1 mrad raised to 10 mrad
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (i != j) {
        EXPECT_EQ(f(i, j), cov(i, j));
      }
    }
  }
}

}  // namespace
}  // namespace urbanslam::esdf
