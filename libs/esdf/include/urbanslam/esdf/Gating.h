#pragma once
// Innovation gating: a loop closure is accepted only when its innovation is consistent with the
// filter's uncertainty, d^2 = nu' S^-1 nu <= chi2 quantile(p, dof), S = H P H' + R. A false loop
// closure in an information filter cannot be undone cheaply, so it is rejected before it
// touches Lambda.
#include <Eigen/Core>

namespace urbanslam::esdf {

// Regularised lower incomplete gamma P(a, x) (series / continued fraction, Numerical Recipes
// style), so chi2 CDF(x; k) = P(k/2, x/2).
double regularisedGammaP(double a, double x);
double chi2Cdf(double x, int dof);
// The p-quantile of the chi-square distribution with dof degrees of freedom (bisection on the
// CDF to 1e-12 relative; p in (0, 1)).
double chi2Quantile(double p, int dof);

struct GateResult {
  bool accepted = true;
  double mahalanobis2 = 0;  // d^2
  double threshold = 0;     // chi2 quantile used
  // False when the test was decided by the bound d^2 <= nu' R^-1 nu (S >= R), in which case
  // mahalanobis2 holds that bound and no covariance was recovered. (A closure refused with a
  // conservative covariance holds that covariance's d^2, a lower bound of the exact one.)
  bool covariance_used = true;
};

// d^2 of innovation nu with covariance s against the p-quantile (dof = nu.size()).
GateResult mahalanobisGate(const Eigen::VectorXd& nu, const Eigen::MatrixXd& s, double probability);
// The same against a quantile computed once by the caller (the bisection is not free per gate).
GateResult mahalanobisGateAt(const Eigen::VectorXd& nu, const Eigen::MatrixXd& s, double threshold);

}  // namespace urbanslam::esdf
