#include "urbanslam/esdf/MotionModels.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <stdexcept>

namespace urbanslam::esdf {

Vec3 SteeringModel::predict(const Vec3& x, const VecU& u, double dt, Mat3* f_x, MatU* f_u) const {
  const double v = u(0), steer = u(1), wb = opt_.wheelbase_m;
  const double ca = std::cos(x.z() + steer), sa = std::sin(x.z() + steer);
  if (f_x) {
    *f_x << 1, 0, -dt * v * sa, 0, 1, dt * v * ca, 0, 0, 1;
  }
  if (f_u) {
    f_u->resize(3, 2);
    *f_u << dt * ca, -dt * v * sa, dt * sa, dt * v * ca, dt * std::sin(steer) / wb, dt * v * std::cos(steer) / wb;
  }
  return {x.x() + dt * v * ca, x.y() + dt * v * sa, x.z() + dt * v * std::sin(steer) / wb};
}

Vec3 TurnRateModel::predict(const Vec3& x, const VecU& u, double dt, Mat3* f_x, MatU* f_u) const {
  const double a = opt_.laser_offset_a_m, b = opt_.laser_offset_b_m, h = opt_.laser_offset_h_m;
  const double c = std::cos(x.z()), s = std::sin(x.z());
  const double t1 = a * s + b * c, t2 = a * c - b * s;  // eqs. 2.13b, 2.13c
  const double v = u(0), w = u(1);
  // Eq. 2.13a: the input matrix G(phi) with x(k+1) = x(k) + Ts G u.
  const double g12 = -h * c - t1, g22 = -h * s + t2;
  if (f_x) {
    *f_x << 1, 0, dt * (-s * v + (h * s - t2) * w), 0, 1, dt * (c * v - (h * c + t1) * w), 0, 0, 1;
  }
  if (f_u) {
    f_u->resize(3, 2);
    *f_u << dt * c, dt * g12, dt * s, dt * g22, 0, dt;
  }
  return {x.x() + dt * (c * v + g12 * w), x.y() + dt * (s * v + g22 * w), x.z() + dt * w};
}

Vec3 OdometryModel::predict(const Vec3& x, const VecU& u, double, Mat3* f_x, MatU* f_u) const {
  const Vec3 d(u(0), u(1), u(2));
  if (f_x || f_u) {
    Mat3 j1, j2;
    composeJacobians(x, d, &j1, &j2);
    if (f_x) *f_x = j1;
    if (f_u) *f_u = j2;
  }
  return compose(x, d);
}

Mat3 processCovariance(const MatU& f_u, const MatQ& q_v, const Vec3& q_s) {
  Mat3 q = f_u * q_v * f_u.transpose();
  q.diagonal() += q_s;
  return q;
}

Mat3 processInformation(const MatU& f_u, const MatQ& q_v, const Vec3& q_s) {
  if ((q_s.array() > 0).all()) {
    const Vec3 qs_inv = q_s.cwiseInverse();
    const MatU qsi_fu = qs_inv.asDiagonal() * f_u;          // Q_s^-1 F_u
    MatQ inner = q_v.inverse() + f_u.transpose() * qsi_fu;  // 2x2 (or 3x3)
    Mat3 info = -qsi_fu * inner.ldlt().solve(qsi_fu.transpose());
    info.diagonal() += qs_inv;
    return 0.5 * (info + info.transpose());
  }
  if ((q_s.array() != 0).any()) throw std::invalid_argument("stabilising noise must be all > 0 or all 0");
  const Mat3 q = f_u * q_v * f_u.transpose();
  // Rank test on the eigenvalues: an LDLT of a rank-2 matrix succeeds with a tiny pivot.
  Eigen::SelfAdjointEigenSolver<Mat3> eig(q);
  const Vec3 ev = eig.eigenvalues();
  if (!(ev.minCoeff() > 1e-12 * ev.maxCoeff()))
    throw std::invalid_argument("process noise F_u Q_v F_u' is singular; set a stabilising noise");
  const Mat3 info = q.ldlt().solve(Mat3::Identity());
  return 0.5 * (info + info.transpose());
}

}  // namespace urbanslam::esdf
