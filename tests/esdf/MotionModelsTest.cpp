// Motion models (thesis 2.2): analytic F_x, F_u vs numerical; process information (eq. 2.20)
// vs the direct inverse of Q_s + F_u Q_v F_u'.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <memory>

#include "TestUtil.h"
#include "urbanslam/esdf/MotionModels.h"

namespace urbanslam::esdf {
namespace {

using V = Eigen::VectorXd;

void checkModel(const MotionModel& m, const VecU& u, double dt, std::mt19937& rng) {
  for (int t = 0; t < 30; ++t) {
    const Vec3 x = test::randomPose(rng);
    Mat3 fx;
    MatU fu;
    const Vec3 y = m.predict(x, u, dt, &fx, &fu);
    EXPECT_LT((y - m.predict(x, u, dt, nullptr, nullptr)).norm(), 1e-15);
    const auto nx = test::numericalJacobian([&](const V& p) -> V { return m.predict(p, u, dt, nullptr, nullptr); }, x);
    const auto nu = test::numericalJacobian([&](const V& q) -> V { return m.predict(x, VecU(q), dt, nullptr, nullptr); }, V(u));
    EXPECT_LT((fx - nx).norm(), 1e-6) << "F_x\n" << fx << "\nvs\n" << nx;
    EXPECT_LT((fu - nu).norm(), 1e-6) << "F_u\n" << fu << "\nvs\n" << nu;
  }
}

TEST(MotionModels, SteeringJacobians) {
  std::mt19937 rng(10);
  SteeringModel m({2.83});
  checkModel(m, VecU(Eigen::Vector2d(3.0, 0.2)), 0.025, rng);
  checkModel(m, VecU(Eigen::Vector2d(-1.0, -0.4)), 0.2, rng);
}

TEST(MotionModels, TurnRateJacobians) {
  std::mt19937 rng(11);
  TurnRateModel m;  // Victoria Park a, b, h
  checkModel(m, VecU(Eigen::Vector2d(3.0, 0.3)), 0.025, rng);
  checkModel(m, VecU(Eigen::Vector2d(0.5, -1.0)), 0.2, rng);
}

TEST(MotionModels, TurnRateStraightLineIsPureTranslation) {
  TurnRateModel m;
  const Vec3 y = m.predict(Vec3(1, 2, 0.5), VecU(Eigen::Vector2d(2.0, 0.0)), 0.5, nullptr, nullptr);
  EXPECT_NEAR(y.x(), 1 + std::cos(0.5), 1e-12);
  EXPECT_NEAR(y.y(), 2 + std::sin(0.5), 1e-12);
  EXPECT_NEAR(y.z(), 0.5, 1e-12);
}

TEST(MotionModels, OdometryJacobiansAreCompounding) {
  std::mt19937 rng(12);
  OdometryModel m;
  checkModel(m, VecU(Eigen::Vector3d(0.7, -0.1, 0.05)), 0.0, rng);
}

TEST(MotionModels, ProcessInformationByInversionLemmaEqualsDirectInverse) {
  std::mt19937 rng(13);
  SteeringModel m;
  MatQ qv(2, 2);
  qv << 0.04, 0, 0, 0.001;
  const Vec3 qs(1e-3, 1e-3, 1e-4);
  for (int t = 0; t < 20; ++t) {
    Mat3 fx;
    MatU fu;
    m.predict(test::randomPose(rng), VecU(Eigen::Vector2d(2.0, 0.1)), 0.1, &fx, &fu);
    const Mat3 q = processCovariance(fu, qv, qs);
    const Mat3 direct = q.inverse();
    const Mat3 lemma = processInformation(fu, qv, qs);
    EXPECT_LT((lemma - direct).norm() / direct.norm(), 1e-10);
    // Without stabilising noise the two-input Q is singular.
    EXPECT_THROW(processInformation(fu, qv, Vec3::Zero()), std::invalid_argument);
  }
  // The three-input odometry model needs no stabilisation.
  OdometryModel o;
  Mat3 fx;
  MatU fu;
  o.predict(Vec3(1, 2, 0.3), VecU(Eigen::Vector3d(1, 0, 0.1)), 0, &fx, &fu);
  MatQ q3 = Eigen::Vector3d(0.01, 0.02, 0.003).asDiagonal();
  const Mat3 q = processCovariance(fu, q3, Vec3::Zero());
  EXPECT_LT((processInformation(fu, q3, Vec3::Zero()) - q.inverse()).norm() / q.inverse().norm(), 1e-12);
}

}  // namespace
}  // namespace urbanslam::esdf
