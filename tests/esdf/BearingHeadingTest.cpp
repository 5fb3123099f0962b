// The camera's planar relative pose (bearing of the translation + heading change) as a filter
// factor: its Jacobian against central differences, its information against the exact bearing,
// heading and range of perturbed relative poses, and its effect in the filter (the bearing and
// heading pulled to the camera's, the range left to the odometry edge, an inconsistent bearing
// refused by the gate).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "TestUtil.h"
#include "urbanslam/esdf/BearingHeading.h"
#include "urbanslam/esdf/Esdf.h"

namespace urbanslam::esdf {
namespace {

TEST(BearingHeading, JacobianMatchesCentralDifferences) {
  std::mt19937 rng(4);
  for (int k = 0; k < 200; ++k) {
    Vec3 r = test::randomPose(rng, 5.0);
    if (std::hypot(r.x(), r.y()) < 0.5) continue;
    const auto f = [](const Eigen::VectorXd& v) -> Eigen::VectorXd { return bearingHeading(Vec3(v)); };
    const Eigen::MatrixXd num = test::numericalJacobian(f, r);
    EXPECT_LT((num - bearingHeadingJacobian(r)).cwiseAbs().maxCoeff(), 1e-6) << r.transpose();
  }
}

TEST(BearingHeading, FactorInformationIsTheCamerasAndTheOdometrysToSecondOrder) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < 100; ++k) {
    BearingHeading m;
    m.bearing_rad = 3 * u(rng);
    m.heading_rad = 3 * u(rng);
    m.information << 400, 50, 50, 900;  // correlated
    const double range = 2 + 8 * (u(rng) + 1), sigma = 0.1 + 0.2 * (u(rng) + 1);
    const RelativeFactor f = relativeFactor(m, range, sigma);
    // z itself has the measured bearing, heading and range.
    EXPECT_NEAR(bearingHeading(f.z)(0), m.bearing_rad, 1e-12);
    EXPECT_NEAR(f.z.head<2>().norm(), range, 1e-12);
    // A small error e: the relative pose z ⊕ e, its exact bearing, heading and range deviations.
    const Vec3 e = 1e-4 * Vec3(u(rng), u(rng), u(rng));
    const Vec3 rel = compose(f.z, e);
    const Vec2 d(common::wrapToPi(bearingHeading(rel)(0) - m.bearing_rad), rel.z() - m.heading_rad);
    const double dr = rel.head<2>().norm() - range;
    const double expected = d.dot(m.information * d) + dr * dr / (sigma * sigma);
    EXPECT_NEAR(e.dot(f.omega * e), expected, 1e-3 * expected + 1e-12);
    // The error of the filter's relative factor at that pose is e itself.
    EXPECT_LT((relativePoseError(Vec3::Zero(), rel, f.z) - e).norm(), 1e-12);
  }
}

TEST(BearingHeading, InTheFilterBearingAndHeadingFollowTheCameraRangeTheOdometry) {
  Esdf filter;
  filter.initialise(Vec3::Zero(), Mat3::Identity() * 1e-8);
  // Odometry: 5 m straight ahead, but the true motion went 20° to the left and turned 10°.
  const double sxy = 0.5, sphi = 0.3;
  const Mat3 odo_info = Vec3(1 / (sxy * sxy), 1 / (sxy * sxy), 1 / (sphi * sphi)).asDiagonal();
  filter.augmentRelative(0, Vec3(5, 0, 0), odo_info);
  BearingHeading cam;
  cam.bearing_rad = 20 * M_PI / 180;
  cam.heading_rad = 10 * M_PI / 180;
  cam.information = Vec2(1 / std::pow(0.5 * M_PI / 180, 2), 1 / std::pow(0.2 * M_PI / 180, 2)).asDiagonal();
  const RelativeFactor f = relativeFactor(cam, 5.0, weakRangeSigma(5.0));  // the scale is the odometry edge's
  const ObservationResult r = filter.observeRelative(0, 1, f.z, f.omega, true);
  EXPECT_TRUE(r.accepted);
  filter.recover();
  const Vec3 x1 = filter.mean(1);
  const Vec2 bh = bearingHeading(x1);
  EXPECT_NEAR(bh(0), cam.bearing_rad, 0.3 * M_PI / 180);  // the camera's sigma is 0.5°, the odometry's 6°
  EXPECT_NEAR(bh(1), cam.heading_rad, 0.1 * M_PI / 180);
  // The range: the odometry's alone, i.e. where its (5, 0) projects onto the camera's bearing.
  EXPECT_NEAR(x1.head<2>().norm(), 5.0 * std::cos(cam.bearing_rad), 0.02);
  // A camera measurement far outside both: rejected by the gate.
  BearingHeading wrong = cam;
  wrong.bearing_rad = -60 * M_PI / 180;
  const RelativeFactor g = relativeFactor(wrong, 5.0, weakRangeSigma(5.0));
  EXPECT_FALSE(filter.observeRelative(0, 1, g.z, g.omega, true).accepted);
}

}  // namespace
}  // namespace urbanslam::esdf
