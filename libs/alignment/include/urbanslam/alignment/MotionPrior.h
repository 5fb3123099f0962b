#pragma once
// What the odometry says about a scan's pose before the scan is looked at, as a density that
// a scan match can be weighed against: a Gaussian around the odometry's relative pose with the
// motion model's covariance, mixed with a small uniform share over the search window. The
// uniform share is the odometry being wrong in a way its covariance does not describe (a missed
// turn, reversing reported as driving forwards, a wheel slipping on a kerb): a scan match far
// from the odometry then pays a bounded price, -log(outlier share), and wins when the scan
// evidence for it is clearly stronger. Near the odometry the density is the Gaussian, so along
// a direction the scan does not constrain (a corridor) the odometry decides.
#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "urbanslam/common/Pose2.h"

namespace urbanslam::alignment {

class MotionPrior {
 public:
  // mean: the pose of the scan in the reference's frame by the odometry; cov over (x, y, phi);
  // outlier_probability: the uniform share; window_volume: the uniform's support [m² rad].
  MotionPrior(const common::Pose2& mean, const Eigen::Matrix3d& cov, double outlier_probability, double window_volume);

  const common::Pose2& mean() const { return mean_; }
  const Eigen::Matrix3d& information() const { return information_; }
  // (x - mean) with the heading difference wrapped to (-pi, pi].
  Eigen::Vector3d difference(const common::Pose2& x) const;
  double mahalanobis2(const Eigen::Vector3d& difference) const { return difference.dot(information_ * difference); }
  // log of the mixture density as a function of the squared Mahalanobis distance (decreasing).
  double logDensity(double mahalanobis2) const;
  double logDensity(const common::Pose2& x) const { return logDensity(mahalanobis2(difference(x))); }
  // The Gaussian's share of the density at x (the weight of its information in a least-squares
  // refinement: 1 near the odometry, ~0 where only the uniform share explains x).
  double gaussianWeight(double mahalanobis2) const;
  // The smallest squared Mahalanobis distance over the poses whose (x - mean.x, y - mean.y)
  // lies in [dx0, dx1] x [dy0, dy1] with heading difference dphi (exact: a convex quadratic
  // minimised over a rectangle). Bounds the density of a whole block of candidate poses.
  double minMahalanobis2(double dx0, double dx1, double dy0, double dy1, double dphi) const;
  // The same in two steps, for a search that bounds many blocks at each of a few headings: what
  // depends on the heading alone (the quadratic's linear and constant terms, its unconstrained
  // minimum), then the rectangle.
  struct HeadingTerms {
    Eigen::Vector2d b, u;
    double c = 0;
  };
  HeadingTerms headingTerms(double dphi) const;
  double minMahalanobis2(const HeadingTerms& h, double dx0, double dx1, double dy0, double dy1) const;

 private:
  common::Pose2 mean_;
  Eigen::Matrix3d information_;
  double log_gauss_norm_;  // log of the Gaussian's peak density times (1 - outlier share)
  double log_uniform_;     // log of the uniform share's density
  // The position block of the information, factored once: minMahalanobis2 runs for every block
  // of a correlative search (the place search's many windows spent a sixth of their time
  // factoring it again).
  Eigen::LDLT<Eigen::Matrix2d> position_ldlt_;
};

}  // namespace urbanslam::alignment
