#pragma once
// Shared helpers for the ESDF tests: central-difference Jacobians and random numbers.
#include <Eigen/Core>
#include <functional>
#include <random>

namespace urbanslam::esdf::test {

// d f / d x by central differences (f: R^n -> R^m), step h.
inline Eigen::MatrixXd numericalJacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f, const Eigen::VectorXd& x,
                                         double h = 1e-6) {
  const Eigen::VectorXd f0 = f(x);
  Eigen::MatrixXd j(f0.size(), x.size());
  for (int k = 0; k < x.size(); ++k) {
    Eigen::VectorXd xp = x, xm = x;
    xp(k) += h;
    xm(k) -= h;
    j.col(k) = (f(xp) - f(xm)) / (2 * h);
  }
  return j;
}

inline Eigen::Vector3d randomPose(std::mt19937& rng, double range = 10.0) {
  std::uniform_real_distribution<double> u(-range, range), a(-3.1, 3.1);
  return {u(rng), u(rng), a(rng)};
}

inline double gauss(std::mt19937& rng, double sigma) { return std::normal_distribution<double>(0.0, sigma)(rng); }

}  // namespace urbanslam::esdf::test
