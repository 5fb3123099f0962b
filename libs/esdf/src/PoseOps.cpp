#include "urbanslam/esdf/PoseOps.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace urbanslam::esdf {

Vec3 compose(const Vec3& a, const Vec3& b) {
  const double c = std::cos(a.z()), s = std::sin(a.z());
  return {a.x() + c * b.x() - s * b.y(), a.y() + s * b.x() + c * b.y(), a.z() + b.z()};
}

void composeJacobians(const Vec3& a, const Vec3& b, Mat3* j1, Mat3* j2) {
  const double c = std::cos(a.z()), s = std::sin(a.z());
  if (j1) {
    // Rows: x, y, phi of the result; d/dphi_a rotates b by 90 degrees.
    *j1 << 1, 0, -s * b.x() - c * b.y(), 0, 1, c * b.x() - s * b.y(), 0, 0, 1;
  }
  if (j2) {
    *j2 << c, -s, 0, s, c, 0, 0, 0, 1;
  }
}

Vec3 inverse(const Vec3& a) {
  const double c = std::cos(a.z()), s = std::sin(a.z());
  return {-c * a.x() - s * a.y(), s * a.x() - c * a.y(), -a.z()};
}

Mat3 inverseJacobian(const Vec3& a) {
  const double c = std::cos(a.z()), s = std::sin(a.z());
  Mat3 j;
  j << -c, -s, s * a.x() - c * a.y(), s, -c, c * a.x() + s * a.y(), 0, 0, -1;
  return j;
}

Vec3 between(const Vec3& a, const Vec3& b) {
  const double c = std::cos(a.z()), s = std::sin(a.z());
  const double dx = b.x() - a.x(), dy = b.y() - a.y();
  return {c * dx + s * dy, -s * dx + c * dy, common::wrapToPi(b.z() - a.z())};
}

void betweenJacobians(const Vec3& a, const Vec3& b, Mat3* ja, Mat3* jb) {
  // Written out rather than chained through J1⊕ J⊖: same values, one trig evaluation.
  const double c = std::cos(a.z()), s = std::sin(a.z());
  const double dx = b.x() - a.x(), dy = b.y() - a.y();
  if (ja) {
    *ja << -c, -s, -s * dx + c * dy, s, -c, -c * dx - s * dy, 0, 0, -1;
  }
  if (jb) {
    *jb << c, s, 0, -s, c, 0, 0, 0, 1;
  }
}

Mat3 betweenCovariance(const Vec3& a, const Vec3& b, const Eigen::Matrix<double, 6, 6>& joint) {
  Mat3 ja, jb;
  betweenJacobians(a, b, &ja, &jb);
  Eigen::Matrix<double, 3, 6> j;
  j << ja, jb;
  return j * joint * j.transpose();
}

Mat3 withDiagonalFloors(const Mat3& cov, double sigma_xy_m, double sigma_phi_rad) {
  Mat3 out = cov;
  out(0, 0) = std::max(out(0, 0), sigma_xy_m * sigma_xy_m);
  out(1, 1) = std::max(out(1, 1), sigma_xy_m * sigma_xy_m);
  out(2, 2) = std::max(out(2, 2), sigma_phi_rad * sigma_phi_rad);
  return out;
}

double largestPositionSigma(const Mat3& cov) { return std::sqrt(std::max(0.0, cov.topLeftCorner<2, 2>().eigenvalues().real().maxCoeff())); }

Vec3 relativePoseError(const Vec3& a, const Vec3& b, const Vec3& z) { return relativePoseError(a, b, z, nullptr, nullptr); }

Vec3 relativePoseError(const Vec3& a, const Vec3& b, const Vec3& z, Mat3* ja, Mat3* jb) {
  // e = ⊖z ⊕ (⊖a ⊕ b) in closed form: e_t = Rz' (Ra' (t_b - t_a) - t_z), e_phi = phi_b - phi_a -
  // phi_z. Two sine/cosine pairs instead of the three (error) plus four (Jacobians) that
  // chaining compose/inverse/between costs; relinearisation evaluates this for every factor.
  const double ca = std::cos(a.z()), sa = std::sin(a.z());
  const double cz = std::cos(z.z()), sz = std::sin(z.z());
  const double dx = b.x() - a.x(), dy = b.y() - a.y();
  const double hx = ca * dx + sa * dy - z.x(), hy = -sa * dx + ca * dy - z.y();
  const Vec3 e{cz * hx + sz * hy, -sz * hx + cz * hy, common::wrapToPi(b.z() - a.z() - z.z())};
  if (ja || jb) {
    // R' = Rz' Ra' = R(phi_a + phi_z)'; d(Ra' d)/dphi_a = (-sa dx + ca dy, -ca dx - sa dy).
    const double c = cz * ca - sz * sa, s = sz * ca + cz * sa;
    const double gx = -sa * dx + ca * dy, gy = -ca * dx - sa * dy;
    if (ja) {
      *ja << -c, -s, cz * gx + sz * gy, s, -c, -sz * gx + cz * gy, 0, 0, -1;
    }
    if (jb) {
      *jb << c, s, 0, -s, c, 0, 0, 0, 1;
    }
  }
  return e;
}

void relativePoseErrorJacobians(const Vec3& a, const Vec3& b, const Vec3& z, Mat3* ja, Mat3* jb) { relativePoseError(a, b, z, ja, jb); }

}  // namespace urbanslam::esdf
