#pragma once
// Reference for the tests: a dense covariance-form EKF over the same delayed state, written
// directly from the thesis equations (augmentation, prediction, Kalman update). O(n^2) memory
// and O(n^3) time — small problems only.
#include <Eigen/Dense>

#include "urbanslam/esdf/MotionModels.h"
#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::esdf::test {

class DenseEkf {
 public:
  void initialise(const Vec3& mean, const Mat3& cov) {
    x_ = mean;
    p_ = cov;
  }
  int size() const { return static_cast<int>(x_.size() / 3); }
  const Eigen::VectorXd& mean() const { return x_; }
  const Eigen::MatrixXd& covariance() const { return p_; }

  void predictAugment(const MotionModel& m, const VecU& u, const MatQ& qv, double dt, const Vec3& qs) {
    const int n = static_cast<int>(x_.size());
    Mat3 f;
    MatU fu;
    const Vec3 y = m.predict(x_.tail<3>(), u, dt, &f, &fu);
    const Mat3 q = processCovariance(fu, qv, qs);
    Eigen::VectorXd x(n + 3);
    x << x_, y;
    Eigen::MatrixXd p(n + 3, n + 3);
    p.topLeftCorner(n, n) = p_;
    p.topRightCorner(n, 3) = p_.rightCols(3) * f.transpose();
    p.bottomLeftCorner(3, n) = p.topRightCorner(n, 3).transpose();
    p.bottomRightCorner(3, 3) = f * p_.bottomRightCorner(3, 3) * f.transpose() + q;
    x_ = x;
    p_ = p;
  }

  void predict(const MotionModel& m, const VecU& u, const MatQ& qv, double dt, const Vec3& qs) {
    const int n = static_cast<int>(x_.size());
    Mat3 f;
    MatU fu;
    const Vec3 y = m.predict(x_.tail<3>(), u, dt, &f, &fu);
    const Mat3 q = processCovariance(fu, qv, qs);
    const Mat3 pvv = p_.bottomRightCorner(3, 3);
    if (n > 3) {
      const Eigen::MatrixXd ptv = p_.topRightCorner(n - 3, 3) * f.transpose();
      p_.topRightCorner(n - 3, 3) = ptv;
      p_.bottomLeftCorner(3, n - 3) = ptv.transpose();
    }
    p_.bottomRightCorner(3, 3) = f * pvv * f.transpose() + q;
    x_.tail<3>() = y;
  }

  void observeRelative(int i, int j, const Vec3& z, const Mat3& omega) {
    const int n = static_cast<int>(x_.size());
    const Vec3 xi = x_.segment<3>(3 * i), xj = x_.segment<3>(3 * j);
    const Vec3 e0 = relativePoseError(xi, xj, z);
    Mat3 ai, aj;
    relativePoseErrorJacobians(xi, xj, z, &ai, &aj);
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(3, n);
    h.middleCols(3 * i, 3) = ai;
    h.middleCols(3 * j, 3) = aj;
    const Mat3 r = omega.inverse();
    const Eigen::MatrixXd s = h * p_ * h.transpose() + r;
    const Eigen::MatrixXd k = p_ * h.transpose() * s.inverse();
    x_ += k * (-e0);
    const Eigen::MatrixXd ikh = Eigen::MatrixXd::Identity(n, n) - k * h;
    p_ = ikh * p_ * ikh.transpose() + k * r * k.transpose();  // Joseph form
    p_ = 0.5 * (p_ + p_.transpose());
  }

 private:
  Eigen::VectorXd x_;
  Eigen::MatrixXd p_;
};

}  // namespace urbanslam::esdf::test
