#include "urbanslam/slam/MotionIntegrator.h"

#include <cmath>

#include "urbanslam/esdf/MotionModels.h"
#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::slam {

MotionIntegrator::MotionIntegrator(const MotionOptions& motion, const VehicleOptions& vehicle) : motion_(motion), vehicle_(vehicle) {}

void MotionIntegrator::reset() {
  increment_ = {};
  cov_.setZero();
  odometry_sqrt_.setZero();
}

// Σ ← J1 Σ J1' + J2 Q J2' for increment ← increment ⊕ step (Smith–Self–Cheeseman compounding).
void MotionIntegrator::accumulate(const Eigen::Vector3d& step, const Eigen::Matrix3d& step_cov) {
  const esdf::Vec3 inc = esdf::toVec(increment_);
  esdf::Mat3 j1, j2;
  esdf::composeJacobians(inc, step, &j1, &j2);
  cov_ = j1 * cov_ * j1.transpose() + j2 * step_cov * j2.transpose();
  increment_ = esdf::toPose(esdf::compose(inc, step));
}

void MotionIntegrator::addOdometry(const io::OdometryReading& m) {
  have_input_ = true;
  if (have_odom_) {
    const common::Pose2 d = common::between(last_odom_.pose, m.pose);
    const double dist = std::hypot(d.x, d.y), turn = std::abs(d.phi);
    const double sxy = motion_.odometry_sigma_xy_min_m + motion_.odometry_sigma_xy_per_m * dist;
    const double sphi =
        motion_.odometry_sigma_phi_min_rad + motion_.odometry_sigma_phi_per_rad * turn + motion_.odometry_sigma_phi_per_m_rad * dist;
    // Wheel odometry errors are systematic over an increment (a wheel radius, a slipping tyre,
    // a gyro bias): the readings' errors add up linearly, not in quadrature. Compounding a square
    // root of the covariance with the same unit noise for every reading does that; with
    // independent readings the increment's sigma would shrink with the reading rate (FR079's
    // odometry vs its scan matches: 2-5° per keyframe, where independent readings said 0.3°).
    const esdf::Vec3 inc = esdf::toVec(increment_);
    esdf::Mat3 j1, j2;
    esdf::composeJacobians(inc, esdf::Vec3(d.x, d.y, d.phi), &j1, &j2);
    odometry_sqrt_ = j1 * odometry_sqrt_ + j2 * Eigen::Vector3d(sxy, sxy, sphi).asDiagonal().toDenseMatrix();
    cov_ = odometry_sqrt_ * odometry_sqrt_.transpose();
    increment_ = esdf::toPose(esdf::compose(inc, esdf::Vec3(d.x, d.y, d.phi)));
  }
  last_odom_ = m;
  have_odom_ = true;
  odom_ = m.pose;
}

// Speed + steering through the thesis's steering model (eqs. 2.10-2.12), each reading held
// over the interval to the next one.
void MotionIntegrator::addDrive(const io::DriveReading& m) {
  have_input_ = true;
  if (have_drive_) {
    const double dt = m.timestamp - last_drive_.timestamp;
    if (dt > 0 && dt < 1.0) {
      esdf::SteeringModel model({vehicle_.wheelbase_m});
      esdf::VecU u(2);
      u << last_drive_.speed_mps, last_drive_.steering_rad;
      esdf::MatU f_u;
      esdf::Mat3 f_x;
      const esdf::Vec3 step = model.predict(esdf::Vec3::Zero(), u, dt, &f_x, &f_u);
      esdf::MatQ q(2, 2);
      const double ss = motion_.steering_sigma_deg * M_PI / 180.0;
      q << motion_.speed_sigma_mps * motion_.speed_sigma_mps, 0, 0, ss * ss;
      // Q_s keeps the rank-2 F_u Q_v F_u' invertible (eq. 2.21).
      Eigen::Matrix3d step_cov = f_u * q * f_u.transpose();
      step_cov.diagonal() += Eigen::Vector3d(1e-6, 1e-6, 1e-8);
      accumulate(step, step_cov);
      odom_ = common::compose(odom_, esdf::toPose(step));
    }
  }
  last_drive_ = m;
  have_drive_ = true;
}

}  // namespace urbanslam::slam
