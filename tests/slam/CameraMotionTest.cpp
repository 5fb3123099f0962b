// Local SLAM with a camera (slam/CameraMotion.h): the odometry increment weighed against the
// camera's bearing and heading, checked against the true motion the measurements were made from.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/slam/CameraMotion.h"

namespace urbanslam::slam {
namespace {

using esdf::Vec3;

CameraMeasurement cameraSeeing(const Vec3& motion, const common::Pose2& mount, double sb, double sh) {
  // Camera j in camera i's frame, computed directly.
  const Vec3 m = esdf::toVec(mount);
  const Vec3 c = esdf::compose(esdf::inverse(m), esdf::compose(motion, m));
  CameraMeasurement cm;
  cm.mount = mount;
  cm.relative.valid = true;
  cm.relative.bearing_rad = std::atan2(c.y(), c.x());
  cm.relative.heading_rad = c.z();
  cm.relative.cov = Eigen::Vector2d(sb * sb, sh * sh).asDiagonal();
  return cm;
}

TEST(CameraMotion, TheCameraCorrectsTheOdometryHeadingAndSideSlip) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0, 1);
  const common::Pose2 mount{1.0, 0.0, M_PI / 2};  // looking left, as on the simulated car
  double odo_heading = 0, fused_heading = 0, odo_lateral = 0, fused_lateral = 0;
  const int trials = 200;
  for (int k = 0; k < trials; ++k) {
    const Vec3 truth(5.0 + 0.3 * n(rng), 0.2 * n(rng), 0.15 * n(rng));
    KeyframeConstraint odo;
    odo.cov = Eigen::Vector3d(0.25, 0.25, 0.05).asDiagonal();  // 0.5 m, 13 deg
    const Vec3 noisy(truth.x() + 0.5 * n(rng), truth.y() + 0.5 * n(rng), truth.z() + std::sqrt(0.05) * n(rng));
    odo.z = esdf::toPose(noisy);
    const CameraMotionResult r = fuseCameraMotion(odo, cameraSeeing(truth, mount, 0.01, 0.002), 0.9999);
    ASSERT_TRUE(r.used) << k << " chi2 " << r.chi2;
    odo_heading += std::pow(common::wrapToPi(noisy.z() - truth.z()), 2);
    fused_heading += std::pow(common::wrapToPi(r.constraint.z.phi - truth.z()), 2);
    // The lateral error (across the true direction of travel) is what the bearing sees.
    const double dir = std::atan2(truth.y(), truth.x());
    const auto lateral = [&](double x, double y) { return -std::sin(dir) * (x - truth.x()) + std::cos(dir) * (y - truth.y()); };
    odo_lateral += std::pow(lateral(noisy.x(), noisy.y()), 2);
    fused_lateral += std::pow(lateral(r.constraint.z.x, r.constraint.z.y), 2);
    // The posterior is tighter than the odometry alone in heading.
    EXPECT_LT(r.constraint.cov(2, 2), 0.01 * odo.cov(2, 2));
  }
  EXPECT_LT(std::sqrt(fused_heading / trials), 0.005);                      // the camera's 0.1 deg, not the wheels' 13
  EXPECT_LT(std::sqrt(fused_lateral / trials), 0.2 * std::sqrt(odo_lateral / trials));
}

TEST(CameraMotion, ACameraViewTheMotionCannotExplainIsLeftOut) {
  const common::Pose2 mount{1.0, 0.0, M_PI / 2};
  KeyframeConstraint odo;
  odo.z = {5, 0, 0.05};
  odo.cov = Eigen::Vector3d(0.01, 0.01, 0.001).asDiagonal();
  // The camera claims the vehicle turned 40 degrees: far outside the odometry's 2 degrees.
  CameraMeasurement wrong = cameraSeeing(Vec3(5, 0, 0.7), mount, 0.01, 0.002);
  const CameraMotionResult r = fuseCameraMotion(odo, wrong, 0.9999);
  EXPECT_FALSE(r.used);
  EXPECT_GT(r.chi2, 100);
  EXPECT_EQ(r.constraint.z.phi, odo.z.phi);
  // Standing still: the direction of travel is noise, the camera is not used.
  KeyframeConstraint still = odo;
  still.z = {0.05, 0, 0};
  EXPECT_FALSE(fuseCameraMotion(still, cameraSeeing(Vec3(0.05, 0, 0), mount, 0.01, 0.002), 0.9999).used);
}

}  // namespace
}  // namespace urbanslam::slam
