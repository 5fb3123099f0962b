// The camera's bearing + heading as a factor on the vehicle poses (slam/CameraClosure.h), against
// the geometry computed directly: the bearing and heading of camera j seen from camera i, for
// cameras mounted off the vehicle's origin and turned (a side camera).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include <Eigen/LU>

#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/slam/CameraClosure.h"

namespace urbanslam::slam {
namespace {

using esdf::Vec3;

// What the camera sees between the vehicle poses: (bearing, heading) of camera j from camera i.
Eigen::Vector2d seen(const Vec3& xi, const Vec3& xj, const Vec3& mount) {
  const Vec3 c = esdf::between(esdf::compose(xi, mount), esdf::compose(xj, mount));
  return {std::atan2(c.y(), c.x()), c.z()};
}

double chi2(const esdf::RelativeFactor& f, const Vec3& xi, const Vec3& xj) {
  const Vec3 e = esdf::relativePoseError(xi, xj, f.z);
  return e.dot(f.omega * e);
}

TEST(CameraFactor, WeighsTheCameraBearingAndHeadingNotTheRange) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const double sb = 0.02, sh = 0.004;  // rad
  for (int trial = 0; trial < 50; ++trial) {
    const Vec3 mount(1.0 + 0.5 * u(rng), 0.4 * u(rng), M_PI / 2 + 0.3 * u(rng));
    const Vec3 xi(30 * u(rng), 30 * u(rng), M_PI * u(rng));
    const Vec3 xj = esdf::compose(xi, Vec3(8 + 10 * u(rng), 6 * u(rng), 0.5 * u(rng)));
    const Eigen::Vector2d truth = seen(xi, xj, mount);
    CameraMeasurement m;
    m.mount = esdf::toPose(mount);
    m.relative.valid = true;
    m.relative.bearing_rad = truth(0);
    m.relative.heading_rad = truth(1);
    m.relative.cov = Eigen::Vector2d(sb * sb, sh * sh).asDiagonal();
    const esdf::RelativeFactor f = cameraFactor(m, xi, xj);
    EXPECT_LT(chi2(f, xi, xj), 1e-12);

    const Vec3 ci = esdf::compose(xi, mount), cj = esdf::compose(xj, mount);
    const Vec3 c = esdf::between(ci, cj);
    const double range = std::hypot(c.x(), c.y()), bearing = std::atan2(c.y(), c.x());
    const auto vehicleAt = [&](const Vec3& camera_rel) { return esdf::compose(esdf::compose(ci, camera_rel), esdf::inverse(mount)); };
    // Camera j moved sideways by a small bearing change d (same range and heading): (d / sb)^2.
    const double d = 0.5 * sb;
    const Vec3 turned(range * std::cos(bearing + d), range * std::sin(bearing + d), c.z());
    const Vec3 xj_b = vehicleAt(turned);
    EXPECT_NEAR(seen(xi, xj_b, mount)(0) - truth(0), d, 1e-9);
    EXPECT_NEAR(chi2(f, xi, xj_b), (d / sb) * (d / sb), 0.02 * (d / sb) * (d / sb));
    // Camera j turned by a small angle in place: (d / sh)^2.
    const double dh = 0.5 * sh;
    const Vec3 xj_h = vehicleAt(Vec3(c.x(), c.y(), c.z() + dh));
    EXPECT_NEAR(chi2(f, xi, xj_h), (dh / sh) * (dh / sh), 0.02 * (dh / sh) * (dh / sh));
    // Camera j moved along the bearing by a metre: the camera cannot see it; the factor adds
    // next to nothing (the odometry carries the scale).
    const Vec3 xj_r = vehicleAt(Vec3((range + 1) * std::cos(bearing), (range + 1) * std::sin(bearing), c.z()));
    EXPECT_LT(chi2(f, xi, xj_r), 1e-4);
  }
}

// A full camera pose (the length measured too) becomes a full-pose factor on the vehicles: zero at
// the poses that give that camera pose, whatever the estimate; camera j displaced costs its error
// in the measured pose's frame weighed by Σ⁻¹, along the baseline as much as across it.
TEST(CameraFactor, AFullCameraPoseWeighsTheRangeToo) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  const Eigen::Matrix3d cov = Eigen::Vector3d(0.05 * 0.05, 0.02 * 0.02, 0.002 * 0.002).asDiagonal();
  for (int trial = 0; trial < 50; ++trial) {
    const Vec3 mount(1.0 + 0.5 * u(rng), 0.4 * u(rng), M_PI / 2 + 0.3 * u(rng));
    const Vec3 xi(30 * u(rng), 30 * u(rng), M_PI * u(rng));
    const Vec3 xj = esdf::compose(xi, Vec3(8 + 10 * u(rng), 6 * u(rng), 0.5 * u(rng)));
    const Vec3 ci = esdf::compose(xi, mount), c = esdf::between(ci, esdf::compose(xj, mount));
    CameraMeasurement m;
    m.mount = esdf::toPose(mount);
    m.relative.valid = true;
    m.relative.bearing_rad = std::atan2(c.y(), c.x());
    m.relative.heading_rad = c.z();
    m.metric.valid = true;
    m.metric.pose = esdf::toPose(c);
    m.metric.cov = cov;
    // The estimate does not enter: any x_i, x_j give the same factor.
    const esdf::RelativeFactor f = cameraFactor(m, xi, xj), g = cameraFactor(m, Vec3(0, 0, 0), Vec3(100, 0, 0));
    EXPECT_LT((f.z - g.z).norm(), 1e-12);
    EXPECT_LT((f.omega - g.omega).norm(), 1e-9 * f.omega.norm());
    EXPECT_LT(chi2(f, xi, xj), 1e-12);
    const auto vehicleAt = [&](const Vec3& camera_rel) { return esdf::compose(esdf::compose(ci, camera_rel), esdf::inverse(mount)); };
    // Camera j a centimetre further along the baseline (the bearing-heading factor barely sees
    // it): its error in the measured camera pose's frame, weighed by the covariance.
    const double range = std::hypot(c.x(), c.y());
    const Vec3 moved = c + Vec3(c.x() / range * 0.01, c.y() / range * 0.01, 0.0);
    const Vec3 e = esdf::between(c, moved);
    EXPECT_NEAR(chi2(f, xi, vehicleAt(moved)), e.dot(cov.inverse() * e), 0.02 * e.dot(cov.inverse() * e));
    const Vec3 xj_h = vehicleAt(c + Vec3(0, 0, 0.001));
    EXPECT_NEAR(chi2(f, xi, xj_h), 0.25, 0.02 * 0.25);
  }
}

// The scene's depth at the nearest the estimate lets the cameras be: the cameras' distance (not
// the vehicles': a side camera 1 m ahead of the origin of vehicles facing opposite ways) less
// three sigma of the relative position's worst direction, times the images' depth per metre.
TEST(CameraFactor, NearestSceneDepthIsTheClosestBaselineTheEstimateAllowsTimesTheImagesDepth) {
  CameraMeasurement m;
  m.mount = common::Pose2{1.0, 0.0, M_PI / 2};
  m.relative.valid = true;
  m.relative.depth_per_baseline = 4.0;                                 // a facade 40 m away from cameras 10 m apart
  const Vec3 xi(0, 0, 0), xj(30, 0, M_PI);                             // cameras at (1, 0) and (29, 0): 28 m apart
  Eigen::Matrix3d cov = Eigen::Vector3d(4.0, 1.0, 0.01).asDiagonal();  // 2 m along x, 1 m along y
  EXPECT_NEAR(nearestSceneDepth(m, xi, xj, cov), (28.0 - 3 * 2.0) * 4.0, 1e-9);
  cov(0, 0) = 1.0;
  cov(1, 1) = 9.0;  // the worst direction, whichever it is
  EXPECT_NEAR(nearestSceneDepth(m, xi, xj, cov), (28.0 - 3 * 3.0) * 4.0, 1e-9);
  // An estimate that lets them coincide says nothing, even of a scene at infinity.
  cov(1, 1) = 100.0;
  m.relative.depth_per_baseline = std::numeric_limits<double>::infinity();
  EXPECT_EQ(nearestSceneDepth(m, xi, xj, cov), 0.0);
}

TEST(CameraFactor, PinholeOfADownscaledImageProjectsTheSameRays) {
  io::CameraCalibration c;
  c.fx_px = 320;
  c.fy_px = 330;
  c.cx_px = 319.5;
  c.cy_px = 359.5;
  const auto full = pinholeFor(c, 640, 640);
  const auto half = pinholeFor(c, 640, 320);
  EXPECT_DOUBLE_EQ(full.fx, 320);
  EXPECT_DOUBLE_EQ(full.cx, 319.5);
  // A pixel edge at u in the full image is at u / 2 in the half image: a ray through the full
  // image's point (u, v) (pixel centres at integers) passes the half image at ((u + 0.5) / 2 - 0.5, ...).
  for (double u : {0.0, 100.0, 639.0})
    for (double v : {0.0, 250.0, 479.0}) {
      const double xn = (u - full.cx) / full.fx, yn = (v - full.cy) / full.fy;
      const double uh = (u + 0.5) / 2 - 0.5, vh = (v + 0.5) / 2 - 0.5;
      EXPECT_NEAR((uh - half.cx) / half.fx, xn, 1e-12);
      EXPECT_NEAR((vh - half.cy) / half.fy, yn, 1e-12);
    }
}

}  // namespace
}  // namespace urbanslam::slam
