#include "urbanslam/slam/CameraMotion.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>

#include "urbanslam/esdf/Gating.h"
#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::slam {

namespace {

using esdf::Vec3;
using Vec2 = Eigen::Vector2d;
using Mat23 = Eigen::Matrix<double, 2, 3>;

Vec2 wrapped(Vec2 v) {
  v(0) = common::wrapToPi(v(0));
  v(1) = common::wrapToPi(v(1));
  return v;
}

// d(predictedCameraView)/dr by central differences: the map r -> camera view composes two
// rigid motions and an atan2, and a 3-vector costs six evaluations.
Mat23 viewJacobian(const Vec3& r, const common::Pose2& mount) {
  Mat23 j;
  const double h = 1e-6;
  for (int k = 0; k < 3; ++k) {
    Vec3 a = r, b = r;
    a(k) += h;
    b(k) -= h;
    j.col(k) = wrapped(predictedCameraView(a, mount) - predictedCameraView(b, mount)) / (2 * h);
  }
  return j;
}

}  // namespace

Vec2 predictedCameraView(const Vec3& r, const common::Pose2& mount) {
  const Vec3 m = esdf::toVec(mount);
  const Vec3 c = esdf::between(m, esdf::compose(r, m));  // camera j in camera i's frame
  return {std::atan2(c.y(), c.x()), c.z()};
}

CameraMotionResult fuseCameraMotion(const KeyframeConstraint& motion, const CameraMeasurement& camera, double gate_probability,
                                    double min_baseline_m) {
  CameraMotionResult out;
  out.constraint = motion;
  if (!camera.relative.valid) return out;
  const Vec3 z = esdf::toVec(motion.z);
  const Vec3 m = esdf::toVec(camera.mount);
  const Vec3 c = esdf::between(m, esdf::compose(z, m));
  if (std::hypot(c.x(), c.y()) < min_baseline_m) return out;
  const Vec2 y(camera.relative.bearing_rad, camera.relative.heading_rad);
  const Eigen::Matrix2d& cam_cov = camera.relative.cov;
  // Innovation of the camera against the motion's prediction.
  const Mat23 h0 = viewJacobian(z, camera.mount);
  const Eigen::Matrix2d s = h0 * motion.cov * h0.transpose() + cam_cov;
  const Vec2 nu = wrapped(y - predictedCameraView(z, camera.mount));
  out.chi2 = nu.dot(s.ldlt().solve(nu));
  if (!(out.chi2 <= esdf::chi2Quantile(gate_probability, 2))) return out;
  // Gauss-Newton on |r - z|^2_Σ + |view(r) - y|^2_C from r = z (a few steps: the problem is
  // three-dimensional and starts at the prior).
  const Eigen::Matrix3d prior_info = motion.cov.inverse();
  const Eigen::Matrix2d cam_info = cam_cov.inverse();
  Vec3 r = z;
  Eigen::Matrix3d hessian = prior_info;
  for (int it = 0; it < 5; ++it) {
    const Mat23 j = viewJacobian(r, camera.mount);
    const Vec2 e = wrapped(predictedCameraView(r, camera.mount) - y);
    Vec3 d = r - z;
    d(2) = common::wrapToPi(d(2));
    hessian = prior_info + j.transpose() * cam_info * j;
    const Vec3 step = hessian.ldlt().solve(prior_info * d + j.transpose() * cam_info * e);
    r -= step;
    if (step.head<2>().norm() < 1e-9 && std::abs(step(2)) < 1e-10) break;
  }
  out.used = true;
  out.constraint.z = esdf::toPose(r);
  out.constraint.cov = hessian.inverse();
  out.constraint.cov = 0.5 * (out.constraint.cov + out.constraint.cov.transpose());
  return out;
}

}  // namespace urbanslam::slam
