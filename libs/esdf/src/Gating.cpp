#include "urbanslam/esdf/Gating.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace urbanslam::esdf {

double regularisedGammaP(double a, double x) {
  if (x <= 0) return 0.0;
  const double gln = std::lgamma(a);
  if (x < a + 1.0) {
    // Series converges fast below a + 1.
    double ap = a, sum = 1.0 / a, del = sum;
    for (int n = 0; n < 1000; ++n) {
      ap += 1.0;
      del *= x / ap;
      sum += del;
      if (std::fabs(del) < std::fabs(sum) * 1e-16) break;
    }
    return sum * std::exp(-x + a * std::log(x) - gln);
  }
  // Continued fraction (modified Lentz) for Q = 1 - P above a + 1.
  const double tiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 1000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::fabs(del - 1.0) < 1e-16) break;
  }
  return 1.0 - std::exp(-x + a * std::log(x) - gln) * h;
}

double chi2Cdf(double x, int dof) { return regularisedGammaP(0.5 * dof, 0.5 * x); }

double chi2Quantile(double p, int dof) {
  if (!(p > 0 && p < 1) || dof < 1) throw std::invalid_argument("chi2Quantile: need 0 < p < 1, dof >= 1");
  double lo = 0, hi = dof + 10.0;
  while (chi2Cdf(hi, dof) < p) hi *= 2;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (chi2Cdf(mid, dof) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

GateResult mahalanobisGate(const Eigen::VectorXd& nu, const Eigen::MatrixXd& s, double probability) {
  return mahalanobisGateAt(nu, s, chi2Quantile(probability, static_cast<int>(nu.size())));
}

GateResult mahalanobisGateAt(const Eigen::VectorXd& nu, const Eigen::MatrixXd& s, double threshold) {
  GateResult r;
  Eigen::LDLT<Eigen::MatrixXd> ldlt(s);
  r.mahalanobis2 = nu.dot(ldlt.solve(nu));
  r.threshold = threshold;
  r.accepted = std::isfinite(r.mahalanobis2) && r.mahalanobis2 <= r.threshold;
  return r;
}

}  // namespace urbanslam::esdf
