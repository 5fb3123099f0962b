#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "urbanslam/slam/MotionIntegrator.h"

using namespace urbanslam;

// The accumulated covariance must equal a Monte-Carlo estimate of the composed noisy increments,
// the readings' errors being systematic over the increment (one draw, every reading).
TEST(MotionIntegrator, CovarianceMatchesMonteCarlo) {
  slam::MotionOptions mo;
  mo.odometry_sigma_xy_per_m = 0.05;
  mo.odometry_sigma_phi_per_rad = 0.05;
  mo.odometry_sigma_phi_per_m_rad = 0.01;  // small enough for the first-order propagation to hold
  slam::VehicleOptions vo;
  slam::MotionIntegrator mi(mo, vo);
  std::vector<common::Pose2> odo;
  common::Pose2 p;
  for (int i = 0; i < 20; ++i) {
    odo.push_back(p);
    p = common::compose(p, {0.2, 0.0, 0.05});
  }
  for (size_t i = 0; i < odo.size(); ++i) mi.addOdometry({static_cast<double>(i), odo[i]});
  const Eigen::Matrix3d analytic = mi.covariance();
  // Monte Carlo: one error draw per increment, scaled to each reading's sigmas.
  std::mt19937 rng(3);
  std::normal_distribution<double> n01;
  const double sxy = mo.odometry_sigma_xy_min_m + 0.05 * 0.2;
  const double sphi = mo.odometry_sigma_phi_min_rad + 0.05 * 0.05 + mo.odometry_sigma_phi_per_m_rad * 0.2;
  const int kSamples = 20000;
  std::vector<Eigen::Vector3d> ends;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int s = 0; s < kSamples; ++s) {
    common::Pose2 q;
    const double ex = n01(rng), ey = n01(rng), ephi = n01(rng);
    for (int i = 1; i < 20; ++i) q = common::compose(q, {0.2 + sxy * ex, sxy * ey, 0.05 + sphi * ephi});
    ends.emplace_back(q.x, q.y, q.phi);
    mean += ends.back();
  }
  mean /= kSamples;
  Eigen::Matrix3d mc = Eigen::Matrix3d::Zero();
  for (const auto& e : ends) mc += (e - mean) * (e - mean).transpose();
  mc /= kSamples - 1;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(analytic(r, c), mc(r, c), 0.08 * std::sqrt(mc(r, r) * mc(c, c))) << r << "," << c;
  EXPECT_NEAR(mi.increment().x, mean.x(), 0.02);
}

// Speed + steering through the steering model: straight at 2 m/s for 1 s is 2 m ahead.
TEST(MotionIntegrator, SteeringModelIntegratesDriveReadings) {
  slam::MotionOptions mo;
  slam::VehicleOptions vo;
  slam::MotionIntegrator mi(mo, vo);
  for (int i = 0; i <= 40; ++i) mi.addDrive({i * 0.025, 2.0, 0.0});
  EXPECT_NEAR(mi.increment().x, 2.0, 1e-9);
  EXPECT_NEAR(mi.increment().y, 0.0, 1e-9);
  EXPECT_GT(mi.covariance()(0, 0), 0);
  // A constant steering angle drives a circle of radius L / tan(steer).
  slam::MotionIntegrator turn(mo, vo);
  const double steer = 0.2, v = 1.0, dt = 0.01;
  const int steps = 1000;
  for (int i = 0; i <= steps; ++i) turn.addDrive({i * dt, v, steer});
  const double expected_heading = v * steps * dt * std::sin(steer) / vo.wheelbase_m;
  EXPECT_NEAR(turn.increment().phi, expected_heading, 1e-9);
}
