// The sparse information filter against a dense covariance-form EKF implementing the same
// equations, on random small problems: means and covariances must agree to 1e-9.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <memory>

#include "DenseEkf.h"
#include "TestUtil.h"
#include "urbanslam/esdf/Esdf.h"

namespace urbanslam::esdf {
namespace {

double relDiff(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

void runScenario(unsigned seed, bool with_predict_without_augmentation) {
  std::mt19937 rng(seed);
  EsdfOptions opt;
  opt.relinearise = false;  // the EKF linearises once; so must the filter for equality
  opt.stabilising_noise_xy_m2 = 1e-4;
  opt.stabilising_noise_phi_rad2 = 1e-5;
  Esdf esdf(opt);
  test::DenseEkf ekf;
  const Vec3 x0 = test::randomPose(rng, 2.0);
  const Mat3 p0 = Vec3(0.01, 0.02, 0.001).asDiagonal();
  esdf.initialise(x0, p0);
  ekf.initialise(x0, p0);

  auto steering = std::make_shared<SteeringModel>();
  auto turn = std::make_shared<TurnRateModel>();
  auto odo = std::make_shared<OdometryModel>();
  const Vec3 qs2(opt.stabilising_noise_xy_m2, opt.stabilising_noise_xy_m2, opt.stabilising_noise_phi_rad2);

  for (int step = 0; step < 40; ++step) {
    const int kind = step % 3;
    std::shared_ptr<const MotionModel> model = kind == 0   ? std::shared_ptr<const MotionModel>(steering)
                                               : kind == 1 ? std::shared_ptr<const MotionModel>(turn)
                                                           : std::shared_ptr<const MotionModel>(odo);
    VecU u;
    MatQ qv;
    double dt = 0.1;
    Vec3 qs = qs2;
    if (kind == 2) {
      u = VecU(Eigen::Vector3d(0.5 + test::gauss(rng, 0.2), test::gauss(rng, 0.1), test::gauss(rng, 0.2)));
      qv = MatQ(Eigen::Vector3d(0.01, 0.005, 0.002).asDiagonal());
      qs.setZero();
    } else {
      u = VecU(Eigen::Vector2d(3.0 + test::gauss(rng, 0.5), test::gauss(rng, 0.3)));
      qv = MatQ(Eigen::Vector2d(0.05, 0.003).asDiagonal());
    }
    const bool augment = !with_predict_without_augmentation || step % 4 != 3 || esdf.size() < 3;
    if (augment) {
      esdf.predictAugment(model, u, qv, dt);
      ekf.predictAugment(*model, u, qv, dt, qs);
    } else {
      esdf.predict(model, u, qv, dt);
      ekf.predict(*model, u, qv, dt, qs);
    }
    ASSERT_EQ(esdf.size(), ekf.size());
    // A loop closure every few steps between a random old pose and the current one, and now
    // and then between two old poses.
    if (step % 5 == 4) {
      const int n = esdf.size();
      std::uniform_int_distribution<int> pick(0, n - 2);
      const int i = pick(rng);
      const int j = (step % 10 == 9) ? std::max(0, pick(rng) - 1) : n - 1;
      if (i != j) {
        const Vec3 truth = between(ekf.mean().segment<3>(3 * i), ekf.mean().segment<3>(3 * j));
        const Vec3 z = truth + Vec3(test::gauss(rng, 0.2), test::gauss(rng, 0.2), test::gauss(rng, 0.05));
        const Mat3 omega = Vec3(25.0, 25.0, 400.0).asDiagonal();
        esdf.observeRelative(i, j, z, omega);
        ekf.observeRelative(i, j, z, omega);
        esdf.recover();  // the EKF has its mean at once; the ESDF linearises the next step at it
      }
    }
  }
  esdf.recover();
  const Eigen::VectorXd mu = esdf.state().denseMean();
  EXPECT_LT(relDiff(mu, ekf.mean()), 1e-9);
  const Eigen::MatrixXd sigma = esdf.state().denseInformation().inverse();
  EXPECT_LT(relDiff(sigma, ekf.covariance()), 1e-9);
  // eta = Lambda mu (eq. 2.5) after recovery.
  EXPECT_LT(relDiff(esdf.state().denseInformation() * mu, esdf.state().denseEta()), 1e-9);
  // CHOLMOD column-solve covariances against the EKF's P.
  const int n = esdf.size();
  for (int i = 0; i < n; i += 3) {
    const Mat6 joint = esdf.jointCovariance(i, n - 1);
    Mat6 ref;
    ref << ekf.covariance().block<3, 3>(3 * i, 3 * i), ekf.covariance().block<3, 3>(3 * i, 3 * (n - 1)),
        ekf.covariance().block<3, 3>(3 * (n - 1), 3 * i), ekf.covariance().block<3, 3>(3 * (n - 1), 3 * (n - 1));
    EXPECT_LT(relDiff(joint, ref), 1e-9);
  }
}

TEST(EsdfVsEkf, AugmentingFilterMatchesDenseEkf) {
  for (unsigned seed = 100; seed < 110; ++seed) {
    SCOPED_TRACE(seed);
    runScenario(seed, false);
  }
}

TEST(EsdfVsEkf, PredictionWithoutAugmentationMatchesDenseEkf) {
  for (unsigned seed = 200; seed < 210; ++seed) {
    SCOPED_TRACE(seed);
    runScenario(seed, true);
  }
}

TEST(EsdfVsEkf, PredictionWithAugmentationIsConstantSize) {
  // Each augmentation adds exactly one pose and one link, whatever the length of the trajectory.
  Esdf esdf;
  esdf.initialise(Vec3::Zero(), Mat3::Identity() * 1e-4);
  auto odo = std::make_shared<OdometryModel>();
  const MatQ qv = MatQ(Eigen::Vector3d(0.01, 0.01, 0.001).asDiagonal());
  for (int k = 0; k < 1000; ++k) {
    const long long links = esdf.state().linkCount();
    esdf.predictAugment(odo, VecU(Eigen::Vector3d(1, 0, 0.01)), qv, 0);
    EXPECT_EQ(esdf.state().linkCount(), links + 1);
    EXPECT_EQ(esdf.state().links(esdf.currentPose()).size(), 1u);
  }
}

}  // namespace
}  // namespace urbanslam::esdf
