#include "urbanslam/alignment/MotionPrior.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

namespace urbanslam::alignment {

MotionPrior::MotionPrior(const common::Pose2& mean, const Eigen::Matrix3d& cov, double outlier_probability, double window_volume)
    : mean_(mean), information_(cov.inverse()), position_ldlt_(information_.topLeftCorner<2, 2>()) {
  const double p = std::clamp(outlier_probability, 0.0, 1.0);
  log_gauss_norm_ =
      p < 1 ? std::log1p(-p) - 1.5 * std::log(2 * M_PI) - 0.5 * std::log(cov.determinant()) : -std::numeric_limits<double>::infinity();
  log_uniform_ = p > 0 && window_volume > 0 ? std::log(p / window_volume) : -std::numeric_limits<double>::infinity();
}

Eigen::Vector3d MotionPrior::difference(const common::Pose2& x) const {
  return {x.x - mean_.x, x.y - mean_.y, common::wrapToPi(x.phi - mean_.phi)};
}

double MotionPrior::logDensity(double m2) const {
  const double g = log_gauss_norm_ - 0.5 * m2;
  const double hi = std::max(g, log_uniform_), lo = std::min(g, log_uniform_);
  if (!std::isfinite(hi)) return hi;
  return hi + std::log1p(std::exp(lo - hi));  // log(exp(g) + exp(u)) without overflow
}

double MotionPrior::gaussianWeight(double m2) const {
  const double g = log_gauss_norm_ - 0.5 * m2;
  if (!std::isfinite(log_uniform_)) return 1.0;
  return 1.0 / (1.0 + std::exp(log_uniform_ - g));
}

MotionPrior::HeadingTerms MotionPrior::headingTerms(double dphi) const {
  HeadingTerms h;
  h.b = information_.topRightCorner<2, 1>() * dphi;
  h.c = information_(2, 2) * dphi * dphi;
  h.u = -position_ldlt_.solve(h.b);
  return h;
}

double MotionPrior::minMahalanobis2(double dx0, double dx1, double dy0, double dy1, double dphi) const {
  return minMahalanobis2(headingTerms(dphi), dx0, dx1, dy0, dy1);
}

double MotionPrior::minMahalanobis2(const HeadingTerms& h, double dx0, double dx1, double dy0, double dy1) const {
  // q(u) = u' A u + 2 b' u + c over u = (dx, dy) with the heading fixed.
  const Eigen::Matrix2d A = information_.topLeftCorner<2, 2>();
  const Eigen::Vector2d& b = h.b;
  const double c = h.c;
  const auto q = [&](double x, double y) {
    return A(0, 0) * x * x + 2 * A(0, 1) * x * y + A(1, 1) * y * y + 2 * (b(0) * x + b(1) * y) + c;
  };
  // The unconstrained minimum, when it lies inside the rectangle.
  const Eigen::Vector2d& u = h.u;
  if (u(0) >= dx0 && u(0) <= dx1 && u(1) >= dy0 && u(1) <= dy1) return std::max(0.0, q(u(0), u(1)));
  // Otherwise on an edge: a 1D convex quadratic on each, minimised by clamping.
  double best = std::numeric_limits<double>::infinity();
  for (double x : {dx0, dx1}) {
    const double y = std::clamp(-(A(0, 1) * x + b(1)) / A(1, 1), dy0, dy1);
    best = std::min(best, q(x, y));
  }
  for (double y : {dy0, dy1}) {
    const double x = std::clamp(-(A(0, 1) * y + b(0)) / A(0, 0), dx0, dx1);
    best = std::min(best, q(x, y));
  }
  return std::max(0.0, best);
}

}  // namespace urbanslam::alignment
